#pragma once
/// @file gp_io.hpp
/// Saving and loading fitted GPs in HDF5, kept out of the GP types
/// (docs/architecture.md#conventions-of-the-code).
///
/// Layout of one fitted GP in group G (e.g. "/gp/x_dot"):
///   G attributes: backend (string), format_version (int, 1), input_dim (int),
///                 jitter (double), negative_log_marginal_likelihood (double)
///   G/parameters  (P)      [log l; log sf; log sn; backend extras]
///   G/inputs      (N x D)  the points the model is conditioned on
///   G/targets     (N)
/// Loading re-conditions the named backend on the stored points with the stored parameters, which
/// reproduces the saved model exactly (conditioning is deterministic).

#include <filesystem>
#include <memory>
#include <string>

#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::gp {

/// Writes `model` to group `group` of `file`, creating the file and intermediate groups when missing
/// and replacing an existing group of that name; other objects of an existing file are kept. The edit
/// is atomic (atomic_file.hpp, update_atomically): it happens on a copy that is renamed onto `file`
/// only when complete, so a failure leaves `file` as it was. Throws std::runtime_error naming the
/// file on failure.
void save_fitted_gp(const std::filesystem::path& file, const std::string& group, const FittedGp& model);

/// Reads group `group` of `file` and conditions `backend` on it. Throws std::runtime_error naming the
/// file and the object for a missing group, attribute or dataset, wrong shapes, or a backend name that
/// differs from backend.name(). Bad input files throw DataError (core measurements.hpp, a
/// std::runtime_error): a path that is not a readable regular file of at most kMaxDataFileBytes
/// (input_file.hpp: missing, a directory, a FIFO, a device, a loop of symbolic links, too large), a
/// dataset or attribute declaring more values than the file can hold or than kMaxDatasetValues
/// (dataset_size.hpp, checked before anything is allocated), a scalar attribute holding several
/// values. Every error, including the backend's about the data it is conditioned on
/// (std::invalid_argument stays std::invalid_argument), starts with "<file>:".
std::unique_ptr<FittedGp> load_fitted_gp(const std::filesystem::path& file, const std::string& group,
                                         const GpBackend& backend);

/// Writes the GP of every state of a residual model to `<group>/<i>` (i = 0 .. n-1) in the layout
/// above, plus the attributes `state_dim`, `control_dim` and `dt` on `group`, as one atomic edit of
/// `file` like save_fitted_gp. The simulator is code and is not saved.
void save_residual_model(const std::filesystem::path& file, const std::string& group, const ResidualModel& model);

/// Reads what save_residual_model wrote and rebuilds the model around `simulator` with `backend`.
/// Throws std::runtime_error naming the file and object when a GP is missing or the stored
/// dimensions or dt (1e-6 relative) differ from the simulator's; bad input files as load_fitted_gp.
/// Every error starts with "<file>:".
ResidualModel load_residual_model(const std::filesystem::path& file, const std::string& group,
                                  ResidualModel::SimulatorPtr simulator, const GpBackend& backend);

}  // namespace gpilqg::gp
