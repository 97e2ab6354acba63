#include "gpilqg/experiments/run_experiment.hpp"

#include <fmt/format.h>

#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {
namespace {

/// Data carried into a transfer task keeps its rows but belongs to no iteration of the new task.
TransitionData carried(const TransitionData& data) {
  TransitionData out = data;
  std::fill(out.iteration.begin(), out.iteration.end(), -1);
  return out;
}

const AlgorithmRun* find_run(const std::vector<AlgorithmRun>& runs, const std::string& name) {
  for (const auto& run : runs)
    if (run.name == name) return &run;
  return nullptr;
}

}  // namespace

RunResults run_experiment(const RunConfig& config, const RunOptions& options) {
  RunResults results;
  results.config = config;
  results.options = options;
  results.options.journal = nullptr;  // the journal does not outlive the run
  const RunModels models = make_run_models(config);
  const std::vector<std::string> backends = options.backends.empty() ? std::vector<std::string>{config.gp.backend} : options.backends;
  const auto gp_name = [&](const std::string& backend) {
    return options.backends.empty() ? std::string("gp_ilqg") : "gp_ilqg_" + backend;
  };

  results.tasks.resize(config.tasks.size());
  for (std::size_t s = 0; s < options.seeds.size(); ++s) {
    const std::uint64_t seed = options.seeds[s];
    std::vector<AlgorithmRun> previous_task;
    for (std::size_t t = 0; t < config.tasks.size(); ++t) {
      const RunTask& task = config.tasks[t];
      const QuadraticCost cost = make_task_cost(config, task);
      const auto prefix = fmt::format("[seed {} ({}/{})] ", seed, s + 1, options.seeds.size());
      TaskContext context{config, task, static_cast<int>(t), models, cost, nullptr, options.journal};
      if (options.progress) context.progress = [&](const std::string& line) { options.progress(prefix + line); };
      const auto carried_data = [&](const std::string& name) {
        const AlgorithmRun* earlier = task.transfer ? find_run(previous_task, name) : nullptr;
        return earlier != nullptr ? carried(earlier->data) : TransitionData{};
      };

      std::vector<AlgorithmRun> runs;
      runs.push_back(run_fixed_model(context, "ilqg_real", models.world, seed));
      runs.push_back(run_fixed_model(context, "ilqg_sim", models.simulator, seed));
      for (const auto& backend_name : backends) {
        const auto backend = gp::make_backend(backend_name, config.gp.backend_settings);
        const std::string name = gp_name(backend_name);
        runs.push_back(run_gp_ilqg(context, name, *backend, carried_data(name), seed));
      }
      if (config.pddp) {
        runs.push_back(run_pddp_on_data_of(context, *find_run(runs, gp_name(backends.front())), seed));
        if (config.pddp_own) runs.push_back(run_pddp_own(context, carried_data("pddp_own"), seed));
      }

      TaskResults& out = results.tasks[t];
      if (s == 0) {
        for (const auto& run : runs) out.algorithms.push_back(run.name);
        const AlgorithmRun& gp = *find_run(runs, gp_name(backends.front()));
        if (gp.data.size() > 0 && gp.final_model && dynamic_cast<const gp::ResidualModel*>(gp.final_model.get()))
          out.slice = model_slice(*models.world, *gp.final_model, gp.data);
      }
      previous_task = runs;
      out.seeds.push_back(std::move(runs));
    }
  }
  return results;
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
