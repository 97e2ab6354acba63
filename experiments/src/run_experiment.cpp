#include "gpilqg/experiments/run_experiment.hpp"

#include "gpilqg/experiments/run_units.hpp"

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

}  // namespace gpilqg
