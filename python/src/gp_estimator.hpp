#pragma once
/// @file gp_estimator.hpp
/// The C++ side of gpilqg.GaussianProcess: one GP backend (backend_registry.hpp) with its fit
/// options, and the model it was last fitted to. Nothing here touches Python, so the binding can
/// run every call below with the GIL released.
///
/// Conventions (hyperparameters.hpp): theta = [log l (D); log sf; log sn; backend extras]. The
/// library minimises the negative log marginal likelihood nlml(theta) = -log p(y | X, theta); the
/// estimator reports the log marginal likelihood lml = -nlml and d lml / d theta = -d nlml / d theta.

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/backend_registry.hpp"

namespace gpilqg::python {

/// What an estimator is built from: a backend name with its size settings, and the fit options.
struct GpConfig {
  std::string backend = "exact";
  gp::BackendSettings settings;
  gp::FitOptions fit;
  /// Throws std::invalid_argument (the library's message) for an unknown backend or bad settings.
  void validate() const;
};

/// A conditioned model, the summary of the fit that produced it, and the NLML objective on its
/// training points (built on first use, guarded by a mutex because it owns a workspace).
class GpState {
 public:
  GpState(GpConfig config, gp::FitResult result);

  const std::shared_ptr<const gp::FittedGp>& model() const { return model_; }
  const gp::FitSummary& summary() const { return summary_; }
  /// Number of backend-specific entries after [log l; log sf; log sn] divided by D: FITC's M
  /// pseudo-inputs or SSGP's m spectral points (0 for the exact and compact backends).
  int extra_rows() const;

  /// -nlml(theta) on the model's training points, and d lml / d theta into `gradient` when not null.
  /// Never NaN: a failed factorisation gives -infinity and a zero gradient. Throws
  /// std::invalid_argument for a wrongly sized theta.
  double log_marginal_likelihood(const VectorCRef& theta, Vector* gradient) const;

 private:
  GpConfig config_;
  std::shared_ptr<const gp::FittedGp> model_;
  gp::FitSummary summary_;
  mutable std::mutex mutex_;
  mutable std::unique_ptr<gp::MarginalLikelihoodObjective> objective_;
};

/// Fits the backend's hyperparameters to (X, y) (GpBackend::fit: subsample, NLopt, condition) or,
/// with `theta`, conditions on the training points the backend selects with theta as given (no
/// optimisation, no clipping to the fitter's bounds). Throws std::invalid_argument with the library's
/// message for degenerate data or a bad theta, std::runtime_error when conditioning fails.
std::shared_ptr<const GpState> fit_gp(const GpConfig& config, gp::TrainingSet data,
                                      const std::optional<Vector>& theta);

/// Where predict_gp writes (row-major NumPy buffers; null for outputs not asked for).
struct PredictionBuffers {
  double* mean = nullptr;         ///< N
  double* std = nullptr;          ///< N: sqrt(latent variance)
  double* mean_gradient = nullptr;  ///< N x D, row-major
  double* std_gradient = nullptr;   ///< N x D, row-major: d std / dz = (d variance / dz) / (2 std), 0 where std = 0
};

/// Latent predictions at the rows of `points` (N x D). Throws std::invalid_argument when D differs
/// from the model's.
void predict_gp(const gp::FittedGp& model, const MatrixCRef& points, const PredictionBuffers& out);

}  // namespace gpilqg::python
