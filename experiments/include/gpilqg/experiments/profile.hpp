#pragma once
/// @file profile.hpp
/// `gpilqg profile DATA --backends LIST [--sizes LIST] [--json] [--out F.h5] [--plots DIR]`
/// (DESIGN.md section 8): trains every backend on growing nested subsets of one data set and reports
/// fit time, prediction time and the test scores SMSE, MNLP, MSLL (metrics.hpp, GPML book section 2.5).
///
/// Data (read_profile_data):
///  - the benchmark format (data/gp-benchmarks): datasets X_train (N x D), y_train (N), X_test
///    (M x D), y_test (M), optional group /reference_hyperparameters (dataset log_lengthscales (D),
///    attributes log_signal_std, log_noise_std; ARD squared exponential);
///  - a measurement set (DESIGN.md section 4, CSV or HDF5 with /episodes; needs the system): inputs
///    z = [x; u] of every step t -> t+1, target of one state `output`:
///      residual  (default): x'_measured - phi_sim(x, u), the simulator's one-step error (the "sim"
///                 preset integrated with RK4 at the data's dt), i.e. what the residual model learns;
///      increment: x'_measured - x.
///    Every `test_every`-th sample (from the first; default 5) is held out as the test set.
///
/// Subsets: the first n points of one fixed random permutation of the training set (seeded), so each
/// size contains the smaller ones. Rows: every backend at every size, plus, when the data set has
/// reference hyperparameters, "exact_reference": the exact GP conditioned (no fit) on the same subset
/// with those hyperparameters, the baseline. The exact GP (fitted or reference) needs two dense N x N
/// matrices while fitting (16 N^2 bytes; one when only conditioning); a size whose need exceeds the
/// memory budget is skipped, and the row says so (status "skipped", reason).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/backend_registry.hpp"

namespace gpilqg {

enum class ProfileTarget { Residual, Increment };

struct ProfileDataOptions {
  std::string system;                            ///< measurement sets only: "cartpole" or "quadrotor"
  std::string output;                            ///< measurement sets: state name (default: the first state)
  ProfileTarget target = ProfileTarget::Residual;
  int test_every = 5;                            ///< measurement sets: every k-th sample is a test sample
};

struct ProfileData {
  std::string name;          ///< the file's stem, or the benchmark's `name` attribute
  std::string format;        ///< "benchmark" or "measurements"
  std::string target;        ///< what y is, e.g. "y_train" or "residual of x_dot"
  gp::TrainingSet train;
  Matrix test_inputs;
  Vector test_targets;
  std::optional<gp::Hyperparameters> reference;  ///< /reference_hyperparameters when present
};

/// Reads either format (chosen by content: X_train present -> benchmark; /episodes or .csv ->
/// measurements). Throws InputError or DataError naming the file and the dataset, attribute or field:
/// missing or mis-shaped datasets, non-finite values, a measurement set without `system`, an unknown
/// output name, or too few samples; a path that is not a readable regular file of at most
/// kMaxDataFileBytes (input_file.hpp); a dataset declaring more values than the file can hold or than
/// kMaxDatasetValues (dataset_size.hpp), refused before anything is allocated.
ProfileData read_profile_data(const std::filesystem::path& file, const ProfileDataOptions& options);

struct ProfileOptions {
  std::vector<std::string> backends;     ///< registry names
  std::vector<int> sizes;                ///< training-set sizes; 0 means all
  gp::BackendSettings settings;          ///< exact_points is set to the size for "exact"
  gp::FitOptions fit;                    ///< restarts, max_evaluations, seed
  double memory_budget_bytes = 4.0 * (1ull << 30);  ///< for the exact GP's dense matrices
  std::optional<int> max_test_points;    ///< score on the first n of a fixed permutation of the test set
  /// Start every fit from the reference hyperparameters (the backend's extras at its data-driven
  /// values) besides its own data-driven start; needs reference hyperparameters in the data.
  bool start_from_reference = false;
  /// Throws InputError naming the option.
  void validate(const ProfileData& data) const;
};

struct ProfileRow {
  std::string backend;    ///< registry name, or "exact_reference"
  int size = 0;           ///< training points
  std::string status;     ///< "ok", "skipped" or "failed"
  std::string reason;     ///< why skipped / failed
  double fit_seconds = 0.0;      ///< fit (or conditioning for exact_reference)
  double predict_seconds = 0.0;  ///< mean and variance at all test points
  double smse = 0.0, mnlp = 0.0, msll = 0.0;
  double nlml = 0.0;
  int evaluations = 0;
  std::string termination;
  std::string conditioning;  ///< FactorStatus of the final model
  Vector parameters;         ///< [log l; log sf; log sn] of the model (shared part)
};

struct ProfileReport {
  std::string file;
  ProfileData data;  ///< only name, format, target and sizes are reported
  ProfileOptions options;
  int test_points = 0;
  std::vector<ProfileRow> rows;
};

/// One row of the report: a backend (or "exact_reference") at one training-set size.
struct ProfileCase {
  std::string backend;
  int size = 0;
};

/// The rows run_profile computes, in report order: per size the reference row (when the data has
/// reference hyperparameters), then every backend. Each is independent of the others, so
/// `mpirun -np K gpilqg profile` runs them on K ranks.
std::vector<ProfileCase> profile_cases(const ProfileData& data, const ProfileOptions& options);

/// The report without rows (file, data summary, options, test points); validates the options.
ProfileReport profile_report_header(const std::filesystem::path& file, const ProfileData& data, const ProfileOptions& options);

/// One row: the fit (or, for "exact_reference", the conditioning) on the nested subset of that size,
/// then the scores; a skipped or failed row says why. Throws like run_profile.
ProfileRow run_profile_case(const std::filesystem::path& file, const ProfileData& data, const ProfileOptions& options,
                            const ProfileCase& c);

/// A row as bytes and back, every number bit for bit (rows travel from the ranks to rank 0).
std::string profile_row_bytes(const ProfileRow& row);
ProfileRow profile_row_from_bytes(const std::string& bytes);

/// Runs everything; `progress` (may be empty) gets one line per finished row. A backend that refuses
/// the data (std::invalid_argument, e.g. constant targets) is an InputError starting with `file`.
ProfileReport run_profile(const std::filesystem::path& file, const ProfileData& data, const ProfileOptions& options,
                          const std::function<void(const ProfileRow&)>& progress = {});

/// The peak memory the exact GP needs at n points: 16 n^2 bytes when fitted, 8 n^2 when conditioned.
double exact_memory_bytes(std::int64_t n, bool fitted);

/// {"file", "data": {name, format, target, train_points, test_points, input_dim}, "settings": {...},
///  "rows": [{backend, size, status, reason, fit_s, predict_s, smse, mnlp, msll, nlml, evaluations,
///  termination, conditioning}]} (numbers null for skipped rows).
nlohmann::json profile_json(const ProfileReport& report);
/// A table for the terminal.
std::string format_profile(const ProfileReport& report);

/// HDF5 layout (written to "<file>.tmp-<pid>", renamed into place):
///   / attrs: schema_version (1), gpilqg_version, created, data_file, data_name, target, test_points,
///            train_points, input_dim
///   /rows/{backend (strings), size, status (strings), reason (strings), fit_s, predict_s, smse, mnlp,
///          msll, nlml, evaluations}   one entry per row (NaN where skipped)
/// Throws std::runtime_error naming the file.
void write_profile_hdf5(const std::filesystem::path& file, const ProfileReport& report);

/// Runs experiments/plots/plot_profile.py through run_plot_script (plot_script.hpp): it reads only the
/// HDF5 file and writes <dir>/profile_pareto.png. Throws std::runtime_error when it fails.
void plot_profile(const std::filesystem::path& h5, const std::filesystem::path& directory);

}  // namespace gpilqg
