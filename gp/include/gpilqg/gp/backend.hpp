#pragma once
/// @file backend.hpp
/// The one interface every GP backend implements (docs/gp-backends.md; the rules it keeps:
/// docs/architecture.md#conventions-of-the-code). Three roles, three types:
///
///  - GpBackend: a recipe (options only, no data). `fit(data)` returns a FitResult holding a
///    FittedGp; nothing can be predicted before that.
///  - MarginalLikelihoodObjective: the negative log marginal likelihood of one data set over the
///    backend's parameter vector, with its analytic gradient, bounds and data-driven starting values.
///    This is all the generic fitter (fit.hpp, NLopt) needs, so fitting is written once for all
///    backends. It owns its workspace, so one objective serves one thread.
///  - FittedGp: an immutable conditioned model. Prediction is const and thread-safe; the caller owns
///    the scratch space (Prediction::workspace), so repeated queries do not allocate
///    (docs/architecture.md#models-and-workspaces).
///
/// Parameter vector: [log l (D); log sf; log sn; backend extras] (hyperparameters.hpp).
/// Every GP here is zero-mean on its targets; prior means are handled outside (prior_mean.hpp).
/// Numerical trouble (a Cholesky factor that fails) is a status in the result (jitter added, reported),
/// never an exception in an inner loop and never a NaN (docs/architecture.md#numerical-status).
/// I/O lives in gp_io.hpp.

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/hyperparameters.hpp"
#include "gpilqg/gp/training_set.hpp"

namespace gpilqg::gp {

// ------------------------------------------------------------------------------------------------
// Numerical status

/// Outcome of factorising a covariance matrix (K, or FITC's / SSGP's smaller matrices).
enum class FactorStatus {
  Ok,           ///< factorised as given
  JitterAdded,  ///< factorised after adding `jitter` to the diagonal
  Failed,       ///< not positive definite even with the largest jitter tried
};
std::string_view to_string(FactorStatus status);

/// Escalating jitter: try 0, then `first` * mean(diag), multiplied by `growth` until `last` * mean(diag).
struct JitterSchedule {
  double first = 1e-12;  ///< relative to the mean diagonal entry
  double last = 1e-2;    ///< relative to the mean diagonal entry
  double growth = 10.0;
  void validate() const;  ///< throws std::invalid_argument: need 0 < first <= last, growth > 1
};

// ------------------------------------------------------------------------------------------------
// Prediction

/// Scratch space one prediction needs (backend-specific sizes), owned by the caller so a const model
/// can be shared between threads. Resized on first use only.
struct PredictionWorkspace {
  Vector cross;            ///< k(X, z) (exact: N), k(Xu, z) (FITC: M) or features phi(z) (SSGP: 2m)
  Vector weighted;         ///< the cached inverse applied to `cross`
  Matrix cross_gradient;   ///< d cross / d z when gradients are asked for (rows(cross) x D)
  Vector extra;            ///< any further vector a backend needs
  std::vector<int> indices;  ///< integer scratch (compact: neighbour indices and the sparse solve's reach)
};

/// What to compute besides the mean.
struct PredictionRequest {
  bool variance = true;    ///< the latent variance (exact: O(N^2) on top of the O(N D) mean)
  bool gradients = false;  ///< gradients w.r.t. the test input of everything computed
};

/// Latent (noise-free) prediction at one test input z (D entries). The predictive variance of a new
/// observation is variance + noise variance.
struct Prediction {
  double mean = 0.0;
  double variance = 0.0;      ///< latent variance fs2 >= 0 (clamped at 0 against rounding)
  Vector mean_gradient;       ///< d mean / d z (D), filled only when gradients were requested
  Vector variance_gradient;   ///< d variance / d z (D), filled only when variance and gradients were requested
  PredictionWorkspace workspace;
};

// ------------------------------------------------------------------------------------------------
// Fitted model

/// What conditioning on data found: how the factorisation went and the NLML at the parameters.
struct ConditioningReport {
  FactorStatus status = FactorStatus::Ok;
  double jitter = 0.0;  ///< absolute value added to the diagonal (0 when status == Ok)
  double negative_log_marginal_likelihood = 0.0;
};

class FittedGp {
 public:
  virtual ~FittedGp() = default;

  /// The backend's registry name ("exact", "fitc", "ssgp", ...), written by save().
  virtual std::string_view backend_name() const = 0;
  virtual int input_dim() const = 0;
  /// The points the model is conditioned on (for the exact backend, the subsample).
  virtual const TrainingSet& training_set() const = 0;
  /// [log l; log sf; log sn; extras].
  virtual const Vector& parameters() const = 0;
  virtual const ConditioningReport& conditioning() const = 0;

  /// Prediction at z; fills out.mean and, as requested, out.variance and the gradients (fields not
  /// requested are left as they were). Does not
  /// allocate when `out` has been used with this model before. Throws std::invalid_argument when z
  /// has the wrong size.
  virtual void predict(const VectorCRef& z, Prediction& out, const PredictionRequest& request = {}) const = 0;

  /// Latent mean and variance at every row of `points` (M x D). The default calls the single-point
  /// predict per row; backends may override it with blocked linear algebra.
  virtual void predict(const MatrixCRef& points, Vector& mean, Vector& variance) const;

  Hyperparameters hyperparameters() const;
  /// sf^2: the latent variance far from all data.
  double prior_variance() const { return hyperparameters().signal_variance(); }
  double noise_variance() const { return hyperparameters().noise_variance(); }
  double negative_log_marginal_likelihood() const { return conditioning().negative_log_marginal_likelihood; }
};

// ------------------------------------------------------------------------------------------------
// Objective

/// One evaluation of the negative log marginal likelihood.
/// Contract: when status != Failed, `value` is finite and the gradient (if asked for) is finite;
/// when status == Failed, `value` is +infinity and the gradient is zero. Never NaN.
struct NlmlEvaluation {
  double value = 0.0;
  FactorStatus status = FactorStatus::Ok;
  double jitter = 0.0;  ///< absolute jitter that was needed
};

/// The scratch space of one caller of a likelihood class (FitcLikelihood, SsgpLikelihood; Crocoddyl's
/// model/data split, as StepWorkspace is for a StepModel): made by the likelihood's make_workspace(),
/// owned by the caller (the objective that the optimiser evaluates), used by one thread at a time and
/// reused from evaluation to evaluation. The likelihood itself is immutable and shareable.
struct LikelihoodWorkspace {
  virtual ~LikelihoodWorkspace() = default;
};

/// The objective an optimiser evaluates. It owns the scratch of its evaluations (the exact GP's
/// matrices, a sparse likelihood's LikelihoodWorkspace), hence the non-const evaluate(); one objective
/// serves one thread.
class MarginalLikelihoodObjective {
 public:
  virtual ~MarginalLikelihoodObjective() = default;

  virtual int parameter_count() const = 0;
  /// Input dimension D of the data (the shared part of the vector has D + 2 entries).
  virtual int input_dim() const = 0;
  /// -log p(y | X, theta) and, when `gradient` is not null, d/dtheta (resized to parameter_count()).
  /// Throws std::invalid_argument only for a wrongly sized parameter vector.
  virtual NlmlEvaluation evaluate(const VectorCRef& parameters, Vector* gradient) = 0;
  /// Box bounds for the optimiser.
  virtual ParameterBounds bounds() const = 0;
  /// Data-driven starting values (hyperparameters.hpp: initial_hyperparameters, plus the extras).
  virtual Vector initial_parameters() const = 0;
  /// A random restart point: the default draws log l, log sf, log sn uniformly within +-1.5 of
  /// `initial` (clipped to the bounds) and keeps the extras.
  virtual Vector restart_parameters(const VectorCRef& initial, std::mt19937_64& rng) const;
};

// ------------------------------------------------------------------------------------------------
// Fitting options and summary

struct FitOptions {
  bool optimise = true;            ///< false: condition on the warm start (or the initial values) as given
  int restarts = 2;                ///< random restarts besides the warm start and the initial values
  int max_evaluations = 400;       ///< per start
  double relative_tolerance = 1e-10;  ///< NLopt ftol_rel on the NLML
  double parameter_tolerance = 1e-8;  ///< NLopt xtol_rel
  std::uint64_t seed = 1;          ///< restarts and subsampling draws
  Vector warm_start;               ///< empty, or a parameter vector (previous fit) tried first
  double min_noise_std = 1e-9;     ///< absolute floor on sn (target units), see hyperparameter_bounds
  double min_noise_ratio = 1e-4;   ///< floor on sn relative to the target std, see hyperparameter_bounds
  JitterSchedule jitter;
  /// Wall-clock limit of the whole fit in seconds, 0 for none. Checked after every NLML evaluation
  /// (NLopt's maxtime, each start given the time that is left; no start begins once it is used up):
  /// the fit stops at its first evaluation past the limit with the best point so far
  /// (FitTermination::TimeLimit). Conditioning the returned model comes on top.
  double max_seconds = 0.0;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

enum class FitTermination {
  Converged,       ///< NLopt met a tolerance at the best start
  MaxEvaluations,  ///< the best start ran out of evaluations
  NotOptimised,    ///< FitOptions::optimise was false
  OptimiserError,  ///< NLopt failed at every start; the best point evaluated is used
  TimeLimit,       ///< FitOptions::max_seconds stopped a start or left starts unrun; the best point so far is used
};
std::string_view to_string(FitTermination termination);

struct FitSummary {
  std::string backend;
  int training_points = 0;
  int parameters = 0;
  double initial_nlml = 0.0;     ///< at the first start point
  double nlml = 0.0;             ///< at the returned parameters
  int starts = 0;                ///< starts begun (fewer than planned when the time limit stopped the fit)
  int best_start = 0;            ///< index of the start that won (0: warm start if given, else initial)
  int evaluations = 0;           ///< over all starts
  int jittered_evaluations = 0;  ///< evaluations whose Cholesky needed jitter
  int failed_evaluations = 0;    ///< evaluations that failed even with jitter (the optimiser backtracked)
  double max_jitter = 0.0;       ///< largest jitter any evaluation needed
  FitTermination termination = FitTermination::Converged;
  ConditioningReport conditioning;  ///< of the returned model
  double seconds = 0.0;
  /// e.g. "exact: N=300, nlml 12.3 -> -45.6 in 84 evaluations (3 starts, best 1), converged, no jitter".
  std::string one_line() const;
};

struct FitResult {
  std::unique_ptr<FittedGp> model;
  FitSummary summary;
};

// ------------------------------------------------------------------------------------------------
// Backend

class GpBackend {
 public:
  virtual ~GpBackend() = default;

  /// Registry name, e.g. "exact".
  virtual std::string_view name() const = 0;

  /// Whether objective() and condition() take TrainingSet::noise_variance, a noise variance known per
  /// point; a backend that does not refuses it (refuse_known_noise).
  virtual bool takes_known_noise() const { return false; }

  /// The points one fit uses out of `data`: default all of them; the exact backend draws a uniform
  /// subsample. A different `seed` gives a fresh draw (the paper's re-sample rule).
  virtual TrainingSet select_training_points(const TrainingSet& data, std::uint64_t seed) const;

  /// The NLML objective over this backend's parameter vector for `data` (already selected).
  /// Throws std::invalid_argument for degenerate data (validate_training_set).
  virtual std::unique_ptr<MarginalLikelihoodObjective> objective(const TrainingSet& data,
                                                                 const FitOptions& options) const = 0;

  /// Conditions on `data` with fixed `parameters`, caching what prediction needs. Escalates jitter
  /// per `jitter` when the factorisation fails (reported in FittedGp::conditioning()). Throws
  /// std::invalid_argument for degenerate data or a wrongly sized / non-finite parameter vector, and
  /// std::runtime_error if the factorisation fails even with the largest jitter.
  virtual std::unique_ptr<FittedGp> condition(TrainingSet data, const VectorCRef& parameters,
                                              const JitterSchedule& jitter = {}) const = 0;

  /// select_training_points -> objective -> fit_parameters (fit.hpp) -> condition.
  FitResult fit(const TrainingSet& data, const FitOptions& options = {}) const;
};

}  // namespace gpilqg::gp
