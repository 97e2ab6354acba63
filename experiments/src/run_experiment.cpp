#include "gpilqg/experiments/run_experiment.hpp"

#include "gpilqg/experiments/run_units.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {

RunResults run_experiment(const RunConfig& config, const RunOptions& options) {
  const RunModels models = make_run_models(config);
  const std::vector<RunUnit> units = plan_run_units(config, options);
  std::vector<AlgorithmRun> runs;
  runs.reserve(units.size());
  const CompletedRun completed = [&runs](int index) { return runs.at(static_cast<std::size_t>(index)); };
  for (int i = 0; i < static_cast<int>(units.size()); ++i)
    runs.push_back(run_unit(config, options, models, units, i, completed));
  return assemble_run_results(config, options, models, units, std::move(runs));
}

ModelSlice model_slice(const StepModel& world, const StepModel& model, const TransitionData& data) {
  const auto* residual = dynamic_cast<const gp::ResidualModel*>(&model);
  if (residual == nullptr) throw std::invalid_argument("model_slice: the model is not a GP residual model");
  const int n = residual->state_dim(), m = residual->control_dim(), D = n + m;
  Matrix z(data.size(), D);
  z << data.x, data.u;
  const Vector mean = z.colwise().mean().transpose();
  const Vector spread = ((z.rowwise() - mean.transpose()).cwiseAbs2().colwise().mean().cwiseSqrt().transpose().array() + 1e-9).matrix();

  ModelSlice s;
  double best = -1.0;
  for (int i = 0; i < n; ++i) {
    const double sf2 = residual->output(i).prior_variance();
    if (sf2 > best) best = sf2, s.output = i;
  }
  const Vector log_l = residual->output(s.output).parameters().head(D);
  double shortest = std::numeric_limits<double>::infinity();
  for (int j = 0; j < D; ++j) {
    const double relative = std::exp(log_l(j)) / spread(j);
    if (relative < shortest) shortest = relative, s.input = j;
  }
  Eigen::Index nearest = 0;
  (z.rowwise() - mean.transpose()).rowwise().squaredNorm().minCoeff(&nearest);
  s.base = z.row(nearest).transpose();

  const double lo = z.col(s.input).minCoeff(), hi = z.col(s.input).maxCoeff();
  // Out to where the kernel has forgotten the data: two data widths or six length-scales, whichever is more.
  const double margin = std::max(2.0 * std::max(hi - lo, 1e-3), 6.0 * std::exp(log_l(s.input)));
  constexpr int kPoints = 401;
  s.grid = Vector::LinSpaced(kPoints, lo - margin, hi + margin);
  s.simulator.resize(kPoints), s.mean.resize(kPoints), s.std.resize(kPoints), s.truth.resize(kPoints);
  Vector x_next(n);
  DiffusionColumns columns;
  const auto simulator_ws = residual->simulator().make_workspace();
  const auto residual_ws = residual->make_workspace();
  const auto world_ws = world.make_workspace();
  for (int p = 0; p < kPoints; ++p) {
    Vector zp = s.base;
    zp(s.input) = s.grid(p);
    residual->simulator().step(zp.head(n), zp.tail(m), x_next, nullptr, *simulator_ws);
    s.simulator(p) = x_next(s.output);
    residual->step(zp.head(n), zp.tail(m), x_next, nullptr, *residual_ws);
    s.mean(p) = x_next(s.output);
    world.step(zp.head(n), zp.tail(m), x_next, nullptr, *world_ws);
    s.truth(p) = x_next(s.output);
    residual->uncertainty(zp.head(n), zp.tail(m), columns, false, *residual_ws);
    // G_ii = sqrt(var / dt) (residual_model.hpp), so the per-step std is G_ii sqrt(dt).
    s.std(p) = columns.columns(s.output, s.output) * std::sqrt(residual->dt());
  }
  // Measured transitions whose other inputs lie within one length-scale of the slice's.
  std::vector<double> zs, ys;
  for (int r = 0; r < data.size(); ++r) {
    double distance2 = 0.0;
    for (int j = 0; j < D; ++j)
      if (j != s.input) distance2 += std::pow((z(r, j) - s.base(j)) / std::exp(log_l(j)), 2);
    if (distance2 <= 1.0) zs.push_back(z(r, s.input)), ys.push_back(data.x_next(r, s.output));
  }
  s.data_z = Eigen::Map<const Vector>(zs.data(), static_cast<Eigen::Index>(zs.size()));
  s.data_y = Eigen::Map<const Vector>(ys.data(), static_cast<Eigen::Index>(ys.size()));
  return s;
}

}  // namespace gpilqg
