#include "distributed_run.hpp"

#include <chrono>

#include <fmt/format.h>

#include "gpilqg/experiments/run_units.hpp"

namespace gpilqg::cli {

DistributedRun run_distributed(const MpiSession& session, const RunConfig& config, const RunOptions& options,
                               RunCheckpoint& checkpoint, const std::function<bool()>& stop_signal) {
  if (options.journal != &checkpoint) throw std::logic_error("run_distributed: options.journal must be the checkpoint");
  const RunModels models = make_run_models(config);
  const std::vector<RunUnit> units = plan_run_units(config, options);
  std::vector<std::vector<int>> depends_on;
  std::vector<double> weights;
  for (const auto& unit : units) depends_on.push_back(unit.depends_on), weights.push_back(unit.weight);
  UnitScheduler scheduler(depends_on, weights);

  const CompletedRun completed = [&](int index) {
    return finished_unit_from_journal(config, options, models, units, index);
  };
  const UnitWork work = [&](int index, const std::function<bool()>& stop_requested) {
    checkpoint.set_stop_requested(stop_requested);
    const auto start = std::chrono::steady_clock::now();
    run_unit(config, options, models, units, index, completed);
    if (options.progress)
      options.progress(fmt::format("finished {} in {:.1f} s",
                                   describe_unit(units[static_cast<std::size_t>(index)], config),
                                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
    return std::string();
  };

  DistributedRun out;
  out.distribution = distribute_units(session, scheduler, work, stop_signal);
  if (out.distribution.failed_unit >= 0)
    out.failed_unit = describe_unit(units.at(static_cast<std::size_t>(out.distribution.failed_unit)), config);
  if (session.is_root() && out.distribution.outcome == Distribution::Outcome::Finished) {
    std::vector<AlgorithmRun> runs;
    for (int i = 0; i < static_cast<int>(units.size()); ++i) runs.push_back(completed(i));
    out.results = assemble_run_results(config, options, models, units, std::move(runs));
  }
  return out;
}

}  // namespace gpilqg::cli
