#pragma once
/// @file profile.hpp
/// `gpilqg profile DATA --backends LIST [--sizes LIST] [--json] [--out F.h5] [--plots DIR]`
/// (docs/command-line.md#gpilqg-profile-data---backends-list-options): trains every backend on growing
/// nested subsets of one data set and reports fit time, prediction time and the test scores SMSE, MNLP,
/// MSLL (metrics.hpp, GPML book section 2.5).
///
/// Data (read_profile_data):
///  - the benchmark format (data/gp-benchmarks): datasets X_train (N x D), y_train (N), X_test
///    (M x D), y_test (M), optional group /reference_hyperparameters (dataset log_lengthscales (D),
///    attributes log_signal_std, log_noise_std; ARD squared exponential);
///  - a measurement set (docs/formats.md#measurement-data-csv-and-hdf5, CSV or HDF5 with /episodes;
///    needs the system): inputs z = [x; u] of every step t -> t+1, target of one state `output`:
///      residual  (default): x'_measured - phi_sim(x, u), the simulator's one-step error (the "sim"
///                 preset integrated with RK4 at the data's dt), i.e. what the residual model learns;
///      increment: x'_measured - x.
///    Every `test_every`-th sample (from the first; default 5) is held out as the test set.
///
/// Subsets: the first n points of one fixed random permutation of the training set (seeded), so each
/// size contains the smaller ones. Rows: every backend at every size, plus, when the data set has
/// reference hyperparameters, "exact_reference": the exact GP conditioned (no fit) on the same subset
/// with those hyperparameters, the baseline.
///
/// Budgets (profile_budget.cpp), checked per row before any numeric work; a row over one is skipped
/// and says why (status "skipped", reason):
///  - memory: the row's arrays (profile_row_memory): the exact GP (fitted or reference) needs two
///    dense N x N matrices while fitting (16 N^2 bytes; one when only conditioning), FITC and SSGP
///    their N x M and M x M matrices;
///  - time: the row's predicted seconds, its flop count (ProfileRowWork) over a measured machine rate
///    (gp::dense_flop_rate), above the time budget. A fit that runs anyway and passes the budget stops
///    at its next NLML evaluation with its best point (FitOptions::max_seconds); its row is scored and
///    says so in `reason`.

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
  /// Seconds per row (fit + prediction), 0 for none: a row predicted to take longer is skipped, a fit
  /// that passes it stops at its next NLML evaluation. The default keeps a profile of a few backends
  /// at a few sizes within minutes: with 100 evaluations it admits the exact GP up to N ~ 2,600 at
  /// 15 GFLOP/s (N^3 flops per evaluation), while the cheap rows take seconds.
  double time_budget_seconds = 120.0;
  /// The machine rate for the time budget in flops per second; 0: measured (gp::dense_flop_rate with
  /// settings.threads) the first time a row could exceed the budget on a core of 1 GFLOP/s.
  double flops_per_second = 0.0;
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
  std::string reason;     ///< why skipped / failed, or "stopped at time budget after K evaluations"
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

/// The peak memory of a row's arrays and what holds them, checked against --memory-budget-gb before
/// any work: the exact GP's (exact_memory_bytes); FITC's four M x N matrices and 6 + 2 workers M x M
/// (M = min(inducing, N)); SSGP's Phi and Gamma (N x 2M) and 4 + workers 2M x 2M matrices (M
/// frequencies), workers = settings.threads. nullopt for compact, whose kernel pattern and factor are
/// bounded by its own max_factor_nonzeros (an evaluation over it fails before any numerical work).
struct RowMemory {
  double bytes = 0.0;
  std::string what;  ///< "SSGP at N = 50 with 4096 frequencies (2 N x 2M and 5 2M x 2M matrices)"
};
std::optional<RowMemory> profile_row_memory(const ProfileCase& c, const ProfileOptions& options);

/// The predicted work of one row in flops (counted as the dense linear algebra's: one multiply or add
/// each), with N the size, D the input dimension, T the test points, E = 1 + max_evaluations x starts
/// the most evaluations the fit may make (starts: the data-driven one, the restarts, and the
/// reference when --start reference):
///   exact             per evaluation N^3 (Cholesky N^3/3, inverse from it 2 N^3/3) + N^2 (3 D + 20)
///                     (kernel with its exp, gradient); final 2 N^3/3 (conditioning, L^-1) + T N^2
///                     (variances) + T N (3 D + 20) (cross-covariances); exact_reference: final only;
///   compact           at the fit's first start, from CHOLMOD's symbolic analysis
///                     (gp::CompactBackend::analyze, no numerical work): fl, the flops of one
///                     factorisation, and Z, those of the gradient's sparse inverse subset; per
///                     evaluation fl + Z + nnz(K) (6 D + 40) (kernel values, gradient sums); final
///                     fl + 2 T nnz(L) (a solve through L per test point, the worst case);
///   fitc, ssgp        M = min(inducing, N) for fitc (six N x M by M x M products), M = 2 frequencies
///                     for ssgp (Phi'Phi and Phi A^-1): per evaluation 12 N M^2 (fitc) or 3 N M^2
///                     (ssgp) + 2 N M (3 D + 20) (kernel or features, gradient) + 7 M^3 / 3 (the
///                     M x M Cholesky and the inverse from it, which dominate when M > N); final
///                     4 N M^2 + M^3 / 3 + T (M^2 + M (3 D + 20)).
struct ProfileRowWork {
  double per_evaluation = 0.0;  ///< flops of one NLML evaluation with its gradient
  int evaluations = 0;          ///< E (0 for exact_reference)
  double final = 0.0;           ///< flops of conditioning the returned model and predicting the test set
  std::string what;             ///< the per-evaluation count in words, for the reason
  double total() const { return per_evaluation * evaluations + final; }
};

/// The work of row `c` on `subset` (its nested training set) with `test_points` test points; `fit`
/// is the row's FitOptions (its warm start is the compact backend's first start). Runs the compact
/// backend's symbolic analysis; throws std::invalid_argument for degenerate data like a fit would.
ProfileRowWork profile_row_work(const ProfileCase& c, const gp::TrainingSet& subset, int test_points,
                                const ProfileOptions& options, const gp::FitOptions& fit);

/// Why row `c` is skipped before any numeric work, or empty: over the memory budget
/// (profile_row_memory), or, with a time budget, predicted seconds
/// profile_row_work(...).total() / rate above it, e.g.
///   "predicted 267 s > 120 s time budget (CHOLMOD: 3.8e9 flops per factorisation + 3.6e10 for the
///    gradient's inverse subset, x 101 evaluations + 1.3e10 to condition and predict, at 14.9 GFLOP/s)".
/// The rate is options.flops_per_second, else measured (gp::dense_flop_rate) only when the row needs
/// more than budget x 1e9 flops.
std::string profile_skip_reason(const ProfileCase& c, const gp::TrainingSet& subset, int test_points,
                                const ProfileOptions& options, const gp::FitOptions& fit);

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
///          msll, nlml, evaluations}   one entry per row (0 where skipped); `reason` also says when a
///          fit was stopped at the time budget
/// Throws std::runtime_error naming the file.
void write_profile_hdf5(const std::filesystem::path& file, const ProfileReport& report);

/// Runs experiments/plots/plot_profile.py through run_plot_script (plot_script.hpp): it reads only the
/// HDF5 file and writes <dir>/profile_pareto.png. Throws std::runtime_error when it fails.
void plot_profile(const std::filesystem::path& h5, const std::filesystem::path& directory);

}  // namespace gpilqg
