#include "gpilqg/experiments/run_units.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {
namespace {

constexpr double kFixedModelWeight = 1.0;
constexpr double kLearningLoopWeight = 10.0;

/// The name gp_ilqg runs under: "gp_ilqg" for the config's backend, "gp_ilqg_<backend>" when
/// backends are compared.
std::string gp_name(const RunOptions& options, const std::string& backend) {
  return options.backends.empty() ? std::string("gp_ilqg") : "gp_ilqg_" + backend;
}

std::vector<std::string> backends_of(const RunConfig& config, const RunOptions& options) {
  return options.backends.empty() ? std::vector<std::string>{config.gp.backend} : options.backends;
}

/// Data carried into a transfer task keeps its rows but belongs to no iteration of the new task.
TransitionData carried(const TransitionData& data) {
  TransitionData out = data;
  std::fill(out.iteration.begin(), out.iteration.end(), -1);
  return out;
}

}  // namespace

std::vector<RunUnit> plan_run_units(const RunConfig& config, const RunOptions& options) {
  std::vector<RunUnit> units;
  const std::vector<std::string> backends = backends_of(config, options);
  if (config.gp.known_noise)
    for (const std::string& backend : backends)
      if (!gp::make_backend(backend, config.gp.backend_settings)->takes_known_noise())
        throw InputError(fmt::format("--backends: '{}' with the config's gp.known_noise = true, which it does not take; "
                                     "expected backends among {}, or gp.known_noise = false",
                                     backend, fmt::join(gp::backends_taking_known_noise(), ", ")));
  for (std::size_t s = 0; s < options.seeds.size(); ++s) {
    for (int t = 0; t < static_cast<int>(config.tasks.size()); ++t) {
      const bool transfer = config.tasks[static_cast<std::size_t>(t)].transfer && t > 0;
      const auto add = [&](UnitKind kind, std::string algorithm, std::string backend, double weight) {
        RunUnit unit{s, options.seeds[s], t, kind, std::move(algorithm), std::move(backend), {}, weight};
        // The same algorithm on the previous task of this seed, for a transfer task's initial data.
        if (transfer && (kind == UnitKind::GpIlqg || kind == UnitKind::PddpOwn))
          for (int i = static_cast<int>(units.size()) - 1; i >= 0; --i) {
            const RunUnit& u = units[static_cast<std::size_t>(i)];
            if (u.seed_index == s && u.task == t - 1 && u.algorithm == unit.algorithm) {
              unit.depends_on.push_back(i);
              break;
            }
          }
        units.push_back(std::move(unit));
        return static_cast<int>(units.size()) - 1;
      };
      add(UnitKind::TrueModel, "ilqg_real", "", kFixedModelWeight);
      add(UnitKind::Simulator, "ilqg_sim", "", kFixedModelWeight);
      int first_gp = -1;
      for (const auto& backend : backends) {
        const int index = add(UnitKind::GpIlqg, gp_name(options, backend), backend, kLearningLoopWeight);
        if (first_gp < 0) first_gp = index;
      }
      if (config.pddp) {
        const int index = add(UnitKind::PddpOnGpData, "pddp", "", kLearningLoopWeight);
        units[static_cast<std::size_t>(index)].depends_on.push_back(first_gp);
        if (config.pddp_own) add(UnitKind::PddpOwn, "pddp_own", "", kLearningLoopWeight);
      }
    }
  }
  return units;
}

std::string describe_unit(const RunUnit& unit, const RunConfig& config) {
  return fmt::format("seed {}, task {}, {}", unit.seed, config.tasks.at(static_cast<std::size_t>(unit.task)).name,
                     unit.algorithm);
}

AlgorithmRun run_unit(const RunConfig& config, const RunOptions& options, const RunModels& models,
                      const std::vector<RunUnit>& units, int index, const CompletedRun& completed) {
  const RunUnit& unit = units.at(static_cast<std::size_t>(index));
  const RunTask& task = config.tasks.at(static_cast<std::size_t>(unit.task));
  const QuadraticCost cost = make_task_cost(config, task);
  TaskContext context{config, task, unit.task, models, cost, nullptr, options.journal, options.threads};
  if (options.progress) {
    const auto prefix = fmt::format("[seed {} ({}/{})] ", unit.seed, unit.seed_index + 1, options.seeds.size());
    context.progress = [&options, prefix](const std::string& line) { options.progress(prefix + line); };
  }
  const auto initial_data = [&]() {
    return unit.depends_on.empty() ? TransitionData{} : carried(completed(unit.depends_on.front()).data);
  };
  switch (unit.kind) {
    case UnitKind::TrueModel:
      return run_fixed_model(context, unit.algorithm, models.world, unit.seed);
    case UnitKind::Simulator:
      return run_fixed_model(context, unit.algorithm, models.simulator, unit.seed);
    case UnitKind::GpIlqg: {
      const auto backend = gp::make_backend(unit.backend, config.gp.backend_settings);
      // A transfer task starts from the model the previous task's diagnosis adopted, if any.
      const std::optional<LoopDiagnosis> inherited =
          unit.depends_on.empty() ? std::nullopt : completed(unit.depends_on.front()).diagnosis;
      return run_gp_ilqg(context, unit.algorithm, *backend, initial_data(), unit.seed, inherited);
    }
    case UnitKind::PddpOnGpData:
      return run_pddp_on_data_of(context, completed(unit.depends_on.front()), unit.seed);
    case UnitKind::PddpOwn:
      return run_pddp_own(context, initial_data(), unit.seed);
  }
  throw std::logic_error("run_unit: unknown unit kind");
}

AlgorithmRun finished_unit_from_journal(const RunConfig& config, const RunOptions& options, const RunModels& models,
                                        const std::vector<RunUnit>& units, int index) {
  const RunUnit& unit = units.at(static_cast<std::size_t>(index));
  const RunTask& task = config.tasks.at(static_cast<std::size_t>(unit.task));
  const QuadraticCost cost = make_task_cost(config, task);
  const TaskContext context{config, task, unit.task, models, cost, nullptr, options.journal, options.threads};
  std::optional<AlgorithmRun> run =
      options.journal != nullptr ? options.journal->restore(context, unit.seed, unit.algorithm) : std::nullopt;
  if (!run || static_cast<int>(run->iterations.size()) != config.iterations + 1)
    throw std::runtime_error(fmt::format("{}: no finished run was kept ({})", describe_unit(unit, config),
                                         run ? fmt::format("{} of {} iterations", run->iterations.size(), config.iterations + 1)
                                             : std::string("nothing")));
  if (unit.kind == UnitKind::TrueModel) attach_fixed_model(*run, models.world);
  if (unit.kind == UnitKind::Simulator) attach_fixed_model(*run, models.simulator);
  return std::move(*run);
}

RunResults assemble_run_results(const RunConfig& config, const RunOptions& options, const RunModels& models,
                                const std::vector<RunUnit>& units, std::vector<AlgorithmRun> runs) {
  if (runs.size() != units.size()) throw std::logic_error("assemble_run_results: one run per unit is needed");
  RunResults results;
  results.config = config;
  results.options = options;
  results.options.journal = nullptr;  // the journal does not outlive the run
  results.tasks.resize(config.tasks.size());
  for (auto& task : results.tasks) task.seeds.resize(options.seeds.size());
  const std::string main_gp = gp_name(options, backends_of(config, options).front());
  for (std::size_t i = 0; i < units.size(); ++i) {
    const RunUnit& unit = units[i];
    TaskResults& task = results.tasks[static_cast<std::size_t>(unit.task)];
    if (unit.seed_index == 0) task.algorithms.push_back(unit.algorithm);
    task.seeds[unit.seed_index].push_back(std::move(runs[i]));
  }
  for (auto& task : results.tasks) {
    if (task.seeds.empty()) continue;
    for (const AlgorithmRun& gp : task.seeds.front())
      if (gp.name == main_gp && gp.data.size() > 0 && dynamic_cast<const gp::ResidualModel*>(gp.final_model.get()))
        task.slice = model_slice(*models.world, *gp.final_model, gp.data);
  }
  return results;
}

}  // namespace gpilqg
