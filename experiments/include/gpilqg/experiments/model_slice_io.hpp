#pragma once
/// @file model_slice_io.hpp
/// A ModelSlice in an HDF5 file, the layout of `/<task>/figure1` in a run's result (docs/formats.md),
/// every dataset float64:
///
///   <group>/figure1/{grid, simulator, mean, std, truth} (401): the slice along z_input
///   <group>/figure1/{data_z, data_y, data_residual} (N'): the measurements within one length-scale
///                   of the slice: z_input, x'_output and x'_output - phi_sim(z)_output
///   <group>/figure1/base (n + m): the measured point z* the slice goes through
///   <group>/figure1/length_scales (n + m): the output's ARD length-scales (the slice's metric)
///   attrs: output, input (names), output_unit, input_unit
///
/// Files written before data_residual, length_scales and the unit attributes existed have the rest;
/// experiments/plots/plot_slice.py draws both.

#include <string>

#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/quantity.hpp"
#include "gpilqg/experiments/model_slice.hpp"

namespace gpilqg {

/// Writes `slice` to `<group>/figure1`, naming its output and input from `signature`; nothing when the
/// slice is empty (no learned model). Throws std::invalid_argument when the slice's output or input is
/// not one of the signature's.
void write_model_slice(Hdf5Writer& h5, const std::string& group, const ModelSlice& slice,
                       const SystemSignature& signature);

}  // namespace gpilqg
