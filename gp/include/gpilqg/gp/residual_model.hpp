#pragma once
/// @file residual_model.hpp
/// The simulator as the GP's mean function (GP-ILQG, section "Gaussian Process with the Simulator as
/// a Mean Function"): one GP per state dimension i on inputs z = [x; u] learns the per-step error of
/// the simulator,
///
///   r_i = x'_measured,i - phi_sim,i(x, u)      (= dx - f_sim dt for the paper's Euler simulator),
///
/// and the model is simulator + correction, a StepModel:
///
///   x' = phi_sim(x, u) + mu(z),   A = A_sim + d mu / dx,   B = B_sim + d mu / du,
///   F  = F_sim (process noise passed through),
///   G  = diag(sigma_i(z)),  sigma_i = sqrt(var_i(z) / dt).
///
/// Units of G: the paper models the per-step error eps dt ~ N(eps_hat dt, Sigma dt) (its eq. before
/// (dx-uncertainty)) with Sigma = G G', and the StepModel adds G xi_G sqrt(dt). The GP's latent
/// variance var_i(z) is the variance of the per-step error, i.e. (Sigma dt)_ii, so
/// G_ii = sqrt(var_i / dt) and G_ii^2 dt = var_i. Column i of G is sigma_i e_i with
/// d sigma_i / dz = (d var_i / dz) / (2 sigma_i dt) (zero where var_i has been clamped to 0).
///
/// Far from the data mu -> 0 and var_i -> sf_i^2: the model returns to the simulator with the prior
/// uncertainty (the paper's Figure 1).

#include <memory>
#include <vector>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/step_model.hpp"
#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/resample.hpp"

namespace gpilqg::gp {

namespace detail {
class SharedExactPrediction;
}

/// Inputs and residual targets of all outputs: rows are samples.
struct ResidualData {
  Matrix inputs;     ///< N x (n + m), z = [x; u]
  Matrix residuals;  ///< N x n, x'_measured - phi_sim(x, u)
  /// N x n, or empty: the noise variance of each residual known before the fit, the sensors' and the
  /// simulator's own process noise at that transition (residual_noise_variance, noise_floor.hpp);
  /// output(i) hands column i to its GP (TrainingSet::noise_variance).
  Matrix noise_variance = Matrix();
  int size() const { return static_cast<int>(inputs.rows()); }
  /// The training set of output i.
  TrainingSet output(int i) const;
  /// Rows `indices`.
  ResidualData subset(const std::vector<int>& indices) const;
};

/// (z, residual) pairs from consecutive measurements: row t of x, u and x_next. Throws
/// std::invalid_argument for mismatched shapes or non-finite values.
ResidualData make_residual_data(const StepModel& simulator, const MatrixCRef& x, const MatrixCRef& u,
                                const MatrixCRef& x_next);

/// (z, residual) pairs from consecutive rows of every episode. Throws std::invalid_argument when the
/// set's dimensions differ from the simulator's, or an episode's dt differs from simulator.dt() by
/// more than 1e-6 relative (naming the episode and both values).
ResidualData make_residual_data(const StepModel& simulator, const MeasurementSet& measurements);

/// Whether the outputs share per-query work at prediction time (see ResidualModel).
enum class OutputSharing {
  Auto,  ///< share when every output is an exact GP on the same training inputs (the default)
  Off,   ///< every output predicts on its own through FittedGp::predict (the reference path)
};

struct ResidualModelOptions {
  FitOptions fit;            ///< per output (the seed is offset by the output index for restarts)
  ResampleOptions resample;  ///< used when a validation set is given
  int threads = 2;           ///< outputs fitted concurrently (1: sequential)
  /// Empty, or one lower bound per output on the fitted noise std (target units): output i fits with
  /// min_noise_std = max(fit.min_noise_std, noise_floor(i)). sensor_noise_floor (noise_floor.hpp)
  /// derives it from the sensors and the process noise.
  Vector noise_floor;
  /// Throws std::invalid_argument naming the field; `fit` also checks noise_floor's size.
  void validate() const;
};

/// What fitting each output did.
struct ResidualFitReport {
  std::vector<FitSummary> outputs;         ///< one per state dimension
  std::vector<ResampleReport> resampling;  ///< one per state dimension when a validation set was used
  double seconds = 0.0;
};

class ResidualModel final : public StepModel {
 public:
  using SimulatorPtr = std::shared_ptr<const StepModel>;

  /// Wraps already-fitted GPs, one per state: outputs[i] has input_dim n + m. Throws
  /// std::invalid_argument for a null simulator, a wrong number of outputs or a wrong input dimension.
  ///
  /// Shared prediction: when every output is an exact GP on the same training
  /// inputs X (what fit produces: one subsample for all outputs), the outputs share what depends only
  /// on X and the query z: the squared differences (x_id - z_d)^2 are formed once per query for all
  /// outputs, and the cross-covariances k_a(X, z) once per (x, u) for both step and uncertainty (the DDP
  /// engine calls the two at the same point), so uncertainty does not recompute the means. The
  /// results equal the per-output path's (OutputSharing::Off) to the bit; only the time differs.
  ResidualModel(SimulatorPtr simulator, std::vector<std::unique_ptr<FittedGp>> outputs,
                OutputSharing sharing = OutputSharing::Auto);

  /// Fits one GP per state on `data`, outputs in parallel. All outputs train on the same subsample
  /// (one draw of backend.select_training_points), so they share their inputs. With `validation`
  /// (and `previous`, the previous model), each output follows the paper's re-sample rule
  /// (resample.hpp). With `previous` from the same backend, each output's fit is warm-started from
  /// the previous parameters. `report` (optional) receives every output's fit summary.
  static ResidualModel fit(SimulatorPtr simulator, const ResidualData& data, const GpBackend& backend,
                           const ResidualModelOptions& options = {}, ResidualFitReport* report = nullptr,
                           const ResidualData* validation = nullptr, const ResidualModel* previous = nullptr);

  /// The same from measurements: make_residual_data(*simulator, measurements), then fit.
  static ResidualModel fit(SimulatorPtr simulator, const MeasurementSet& measurements, const GpBackend& backend,
                           const ResidualModelOptions& options = {}, ResidualFitReport* report = nullptr);

  int state_dim() const override { return simulator_->state_dim(); }
  int control_dim() const override { return simulator_->control_dim(); }
  double dt() const override { return simulator_->dt(); }

  /// Holds the simulator's workspace, the outputs' predictions and the shared per-query cache (so
  /// step and uncertainty at the same (x, u) with one workspace share their cross-covariances).
  std::unique_ptr<StepWorkspace> make_workspace() const override;

  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians,
            StepWorkspace& workspace) const override;

  int noise_dim() const override { return simulator_->noise_dim(); }
  using StepModel::noise;
  void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
             StepWorkspace& workspace) const override;

  int uncertainty_dim() const override { return state_dim(); }
  using StepModel::uncertainty;
  void uncertainty(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
                   StepWorkspace& workspace) const override;

  /// Whether the outputs share per-query work (see the constructor).
  bool shares_outputs() const { return shared_ != nullptr; }

  /// The GP of state i.
  const FittedGp& output(int i) const { return *outputs_.at(static_cast<std::size_t>(i)); }
  const StepModel& simulator() const { return *simulator_; }
  const SimulatorPtr& simulator_ptr() const { return simulator_; }

 private:
  SimulatorPtr simulator_;
  std::vector<std::shared_ptr<const FittedGp>> outputs_;
  std::shared_ptr<const detail::SharedExactPrediction> shared_;  // null: per-output prediction
};

}  // namespace gpilqg::gp
