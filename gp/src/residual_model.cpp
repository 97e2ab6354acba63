#include "gpilqg/gp/residual_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "parallel.hpp"
#include "shared_prediction.hpp"

namespace gpilqg::gp {

namespace {

/// The caller's scratch for one ResidualModel: a caller that keeps it never allocates per step once
/// its buffers are warm.
struct ResidualWorkspace final : StepWorkspace {
  std::unique_ptr<StepWorkspace> simulator;
  Vector z;
  std::vector<Prediction> predictions;
  Vector values;     // shared path: the n means or variances
  Matrix gradients;  // shared path: their gradients as rows (n x (n + m))
  detail::SharedExactPrediction::Cache shared;
};

}  // namespace

void ResidualModelOptions::validate() const {
  fit.validate();
  resample.validate();
  if (threads < 1)
    throw std::invalid_argument("ResidualModelOptions::threads = " + std::to_string(threads) + "; expected >= 1");
  if (!((noise_floor.array() >= 0.0).all() && noise_floor.allFinite()))
    throw std::invalid_argument("ResidualModelOptions::noise_floor must be finite and >= 0");
}

ResidualModel::ResidualModel(SimulatorPtr simulator, std::vector<std::unique_ptr<FittedGp>> outputs,
                             OutputSharing sharing)
    : simulator_(std::move(simulator)) {
  if (!simulator_) throw std::invalid_argument("ResidualModel: null simulator");
  const int n = simulator_->state_dim(), m = simulator_->control_dim();
  if (static_cast<int>(outputs.size()) != n)
    throw std::invalid_argument("ResidualModel: " + std::to_string(outputs.size()) + " GPs; expected one per state (" +
                                std::to_string(n) + ")");
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (!outputs[i]) throw std::invalid_argument("ResidualModel: GP " + std::to_string(i) + " is null");
    if (outputs[i]->input_dim() != n + m)
      throw std::invalid_argument("ResidualModel: GP " + std::to_string(i) + " has " +
                                  std::to_string(outputs[i]->input_dim()) + " inputs; expected n + m = " +
                                  std::to_string(n + m) + " (z = [x; u])");
    outputs_.push_back(std::move(outputs[i]));
  }
  if (sharing == OutputSharing::Auto) shared_ = detail::SharedExactPrediction::make(outputs_);
}

ResidualModel ResidualModel::fit(SimulatorPtr simulator, const ResidualData& data, const GpBackend& backend,
                                 const ResidualModelOptions& options, ResidualFitReport* report,
                                 const ResidualData* validation, const ResidualModel* previous) {
  const auto start = std::chrono::steady_clock::now();
  if (!simulator) throw std::invalid_argument("ResidualModel::fit: null simulator");
  options.validate();
  const int n = simulator->state_dim(), m = simulator->control_dim();
  if (data.inputs.cols() != n + m || data.residuals.cols() != n || data.residuals.rows() != data.inputs.rows())
    throw std::invalid_argument("ResidualModel::fit: data has inputs " + std::to_string(data.inputs.rows()) + "x" +
                                std::to_string(data.inputs.cols()) + " and residuals " +
                                std::to_string(data.residuals.rows()) + "x" + std::to_string(data.residuals.cols()) +
                                "; expected N x " + std::to_string(n + m) + " and N x " + std::to_string(n));
  if (previous != nullptr && (previous->state_dim() != n || previous->control_dim() != m))
    throw std::invalid_argument("ResidualModel::fit: the previous model has different dimensions");
  if (options.noise_floor.size() != 0 && options.noise_floor.size() != n)
    throw std::invalid_argument("ResidualModel::fit: noise_floor has " + std::to_string(options.noise_floor.size()) +
                                " entries; expected " + std::to_string(n) + " (one per state) or none");

  std::vector<std::unique_ptr<FittedGp>> outputs(static_cast<std::size_t>(n));
  ResidualFitReport local;
  ResidualFitReport& r = report != nullptr ? *report : local;
  r = ResidualFitReport{};
  r.outputs.resize(static_cast<std::size_t>(n));
  if (validation != nullptr) r.resampling.resize(static_cast<std::size_t>(n));

  const auto fit_output = [&](int i) {
    const auto index = static_cast<std::size_t>(i);
    FitOptions fit_options = options.fit;
    if (options.noise_floor.size() != 0)
      fit_options.min_noise_std = std::max(fit_options.min_noise_std, options.noise_floor(i));
    // Warm start from the previous learner of the same backend (the GP-ILQG loop refits every iteration).
    if (previous != nullptr && previous->output(i).backend_name() == backend.name())
      fit_options.warm_start = previous->output(i).parameters();
    FitResult result;
    if (validation != nullptr) {
      result = fit_with_resampling(backend, data.output(i), validation->output(i),
                                   previous != nullptr ? &previous->output(i) : nullptr, fit_options,
                                   options.resample, &r.resampling[index]);
    } else {
      // The same seed for every output draws the same subsample, so all outputs share their inputs;
      // restarts then differ per output through the offset seed (re-selection is a no-op).
      const TrainingSet selected = backend.select_training_points(data.output(i), options.fit.seed);
      fit_options.seed = options.fit.seed + 7919u * static_cast<std::uint64_t>(i);
      result = backend.fit(selected, fit_options);
    }
    r.outputs[index] = result.summary;
    outputs[index] = std::move(result.model);
  };
  detail::run_indexed(n, options.threads, [&](int i) {
    try {
      fit_output(i);
    } catch (const std::invalid_argument& e) {
      // Name the output: degenerate data (e.g. constant residuals of a state the simulator predicts
      // exactly) is a property of one state, not of the whole data set.
      throw std::invalid_argument("ResidualModel::fit: state " + std::to_string(i) + " of " + std::to_string(n) +
                                  ": " + e.what());
    }
  });
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ResidualModel(std::move(simulator), std::move(outputs));
}

ResidualModel ResidualModel::fit(SimulatorPtr simulator, const MeasurementSet& measurements, const GpBackend& backend,
                                 const ResidualModelOptions& options, ResidualFitReport* report) {
  if (!simulator) throw std::invalid_argument("ResidualModel::fit: null simulator");
  const ResidualData data = make_residual_data(*simulator, measurements);
  return fit(std::move(simulator), data, backend, options, report);
}

std::unique_ptr<StepWorkspace> ResidualModel::make_workspace() const {
  auto ws = std::make_unique<ResidualWorkspace>();
  ws->simulator = simulator_->make_workspace();
  ws->z.resize(state_dim() + control_dim());
  ws->predictions.resize(outputs_.size());
  return ws;
}

void ResidualModel::step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians,
                         StepWorkspace& workspace) const {
  auto& s = workspace_as<ResidualWorkspace>(workspace);
  simulator_->step(x, u, x_next, jacobians, *s.simulator);
  const int n = state_dim(), m = control_dim();
  s.z.head(n) = x;
  s.z.tail(m) = u;
  if (shared_) {
    shared_->means(s.z, s.values, jacobians != nullptr ? &s.gradients : nullptr, s.shared);
    x_next += s.values;
    if (jacobians != nullptr) {
      jacobians->A += s.gradients.leftCols(n);
      jacobians->B += s.gradients.rightCols(m);
    }
    return;
  }
  const PredictionRequest request{false, jacobians != nullptr};
  for (int i = 0; i < n; ++i) {
    Prediction& p = s.predictions[static_cast<std::size_t>(i)];
    outputs_[static_cast<std::size_t>(i)]->predict(s.z, p, request);
    x_next(i) += p.mean;
    if (jacobians != nullptr) {
      jacobians->A.row(i) += p.mean_gradient.head(n).transpose();
      jacobians->B.row(i) += p.mean_gradient.tail(m).transpose();
    }
  }
}

void ResidualModel::noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
                          StepWorkspace& workspace) const {
  simulator_->noise(x, u, out, derivatives, *workspace_as<ResidualWorkspace>(workspace).simulator);
}

void ResidualModel::uncertainty(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
                                StepWorkspace& workspace) const {
  const int n = state_dim(), m = control_dim();
  const double step = dt();
  out.resize(n, m, n);
  auto& s = workspace_as<ResidualWorkspace>(workspace);
  s.z.head(n) = x;
  s.z.tail(m) = u;
  if (shared_) {
    shared_->variances(s.z, s.values, derivatives ? &s.gradients : nullptr, s.shared);
  } else {
    const PredictionRequest request{true, derivatives};
    s.values.resize(n);
    if (derivatives) s.gradients.resize(n, n + m);
    for (int i = 0; i < n; ++i) {
      Prediction& p = s.predictions[static_cast<std::size_t>(i)];
      outputs_[static_cast<std::size_t>(i)]->predict(s.z, p, request);
      s.values(i) = p.variance;
      if (derivatives) s.gradients.row(i) = p.variance_gradient.transpose();
    }
  }
  for (int i = 0; i < n; ++i) {
    // The GP's variance is the per-step error variance (Sigma dt)_ii; G_ii^2 dt = var_i.
    const double sigma = std::sqrt(s.values(i) / step);
    out.columns(i, i) = sigma;
    if (derivatives && sigma > 0.0) {
      const double scale = 1.0 / (2.0 * sigma * step);
      out.d_dx[static_cast<std::size_t>(i)].row(i) = scale * s.gradients.row(i).head(n);
      out.d_du[static_cast<std::size_t>(i)].row(i) = scale * s.gradients.row(i).tail(m);
    }
  }
}

}  // namespace gpilqg::gp
