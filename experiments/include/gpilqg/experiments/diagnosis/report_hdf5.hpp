#pragma once
/// @file report_hdf5.hpp
/// The diagnosis as an HDF5 file, written to a temporary file and renamed into place. The plotting
/// script (experiments/plots/diagnose_plots.py) reads only this file. Layout (schema_version 1):
///
///   / attrs: schema_version, gpilqg_version, system, created, status (the verdict), verdict_effect,
///            consistent (int), model (TOML), model_next (TOML), report (the JSON document),
///            state_names, control_names, input_names, state_units, control_units (string arrays)
///   /data/{x (N x n), u (N x m), x_next (N x n), t (N), episode (N, int), heldout (N, int)}
///   /compare/{predicted, residual, gp_mean, gp_std (N x n)}
///   /compare/states/{rmse, noise_floor, heldout_rmse, fit_percent, gp_explained} (n)
///   /compare/k_<k>/{measured, predicted (W x n), episode, start (W, int), rmse, fit_percent (n)}
///         attrs: k, stride, windows, diverged (one group per horizon of --horizons)
///   /where/relevance, /where/sensitivity (n x (n + m)); /where/episode_rmse (E x n)
///   /where/bins/<input>/{edges (B + 1), rmse (n x B), count (B)}
///   /where/cross_correlation/{lags (2L + 1), values (n x m x (2L + 1)), band (n x m)}
///   /ranking/{estimate, ci_low, ci_high, explained, explained_ci, z_score, heldout_rmse_before,
///             heldout_rmse_after, null_value, identifiable (1/0), interval_holds_null (1/0) (G)}  attrs: heldout_state, effect, parameter_name, unit, aliases (G strings,
///             aliases comma-separated), criterion ("one-step" or "simulation"), window (int samples per
///             window, 1 for one-step), window_restarts (int, simulation_error.hpp)
///   /add/{heldout_rmse (4 x n, rows as attribute model), signal_variance (2 x n: sim+GP, sim+effect+GP),
///         residual_before, residual_after (N x n: "sim" and "sim+effect"), relevance_before (n x (n + m))}
///         attrs: effect, model (4 strings)       (present when the report has the four models)
///   /whiteness/{lags (L + 1, int), autocorrelation (n x (L + 1)), outside_band (n, int), ljung_box_q,
///               p_value (n), white (n, int)}
///         attrs: test ("ljung_box"), band (1.96 / sqrt(samples)), samples, max_lag, level,
///                degrees_of_freedom, critical_value (whiteness.hpp)
///   /free_run/<j>/{t (T), measured (T x n), fit_percent (M x n), steps (M, int), diverged (M, int),
///                  predicted/<model> ((steps + 1) x n: x_0 and the predictions before any divergence)}
///         attrs: id (the episode's id), index (in the file); j = 0, 1, ... the held-out episodes in order
///   /free_run attrs: models (M strings: "sim", ["sim+effect",] "sim+GP"; the rows of fit_percent)
///   /heldout_blocks/{first, last, used_first, used_last (B, int: samples of the record, inclusive),
///                    heldout (B, int), t_start, t_end (B: times of first and last)}
///         attrs: episode (the record's id), samples, gap (samples), gap_time (s). Present for a
///         single-episode record only (heldout_blocks.hpp); every episode above is then a block:
///         episode index and id b are block b, times are the record's, and a k-step window's start
///         counts from its block's used_first.
///
/// Integer-valued datasets (marked int) hold whole numbers stored as float64, like every dataset here.

#include <filesystem>

#include "gpilqg/experiments/diagnosis/diagnosis.hpp"

namespace gpilqg::diagnosis {

/// Writes the report with core's Hdf5Writer, through a temporary file. Throws std::runtime_error
/// naming the file when HDF5 fails.
void write_report_hdf5(const std::filesystem::path& file, const DiagnosisReport& report);

}  // namespace gpilqg::diagnosis
