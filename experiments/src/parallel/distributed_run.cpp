#include "distributed_run.hpp"

#include <chrono>
#include <utility>

#include <fmt/format.h>

#include "gpilqg/experiments/run_units.hpp"
#include "run_session.hpp"

namespace gpilqg::cli {

namespace {

/// A part's models and units; a unit of the whole list is (part, index within the part).
struct PartUnits {
  RunModels models;
  std::vector<RunUnit> units;
  int first = 0;  ///< the index of its first unit in the whole list
};

}  // namespace

DistributedRuns run_distributed(const MpiSession& session, const std::vector<RunPart>& parts,
                                const std::function<bool()>& stop_signal) {
  std::vector<PartUnits> plans;
  std::vector<std::pair<std::size_t, int>> where;  // whole-list index -> (part, unit)
  std::vector<std::vector<int>> depends_on;
  std::vector<double> weights;
  // The same on every rank; a rank that fails here (a model file missing on its machine) stops all.
  every_rank_then_agree(session, [&] {
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const RunPart& part = parts[p];
      if (part.options.journal != part.checkpoint) throw std::logic_error("run_distributed: each part's journal must be its checkpoint");
      PartUnits plan{make_run_models(*part.config), plan_run_units(*part.config, part.options), static_cast<int>(where.size())};
      for (int i = 0; i < static_cast<int>(plan.units.size()); ++i) {
        std::vector<int> deps = plan.units[static_cast<std::size_t>(i)].depends_on;
        for (int& d : deps) d += plan.first;
        depends_on.push_back(std::move(deps));
        weights.push_back(plan.units[static_cast<std::size_t>(i)].weight);
        where.emplace_back(p, i);
      }
      plans.push_back(std::move(plan));
    }
  });
  UnitScheduler scheduler(depends_on, weights);

  const auto completed_of = [&](std::size_t p) -> CompletedRun {
    return [&, p](int index) {
      return finished_unit_from_journal(*parts[p].config, parts[p].options, plans[p].models, plans[p].units, index);
    };
  };
  const auto name_of = [&](int whole) {
    const auto [p, i] = where.at(static_cast<std::size_t>(whole));
    const std::string unit = describe_unit(plans[p].units[static_cast<std::size_t>(i)], *parts[p].config);
    return parts[p].label.empty() ? unit : parts[p].label + ", " + unit;
  };
  const UnitWork work = [&](int whole, const std::function<bool()>& stop_requested) {
    const auto [p, i] = where.at(static_cast<std::size_t>(whole));
    const RunPart& part = parts[p];
    part.checkpoint->set_stop_requested(stop_requested);
    const auto start = std::chrono::steady_clock::now();
    run_unit(*part.config, part.options, plans[p].models, plans[p].units, i, completed_of(p));
    if (part.options.progress)
      part.options.progress(fmt::format("finished {} in {:.1f} s", describe_unit(plans[p].units[static_cast<std::size_t>(i)], *part.config),
                                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
    return std::string();
  };

  DistributedRuns out;
  out.distribution = distribute_units(session, scheduler, work, stop_signal);
  for (const RunPart& part : parts) part.checkpoint->set_stop_requested(stop_signal);  // not the distribution's
  if (out.distribution.failed_unit >= 0) out.failed_unit = name_of(out.distribution.failed_unit);
  if (session.is_root() && out.distribution.outcome == Distribution::Outcome::Finished)
    for (std::size_t p = 0; p < parts.size(); ++p) {
      std::vector<AlgorithmRun> runs;
      for (int i = 0; i < static_cast<int>(plans[p].units.size()); ++i) runs.push_back(completed_of(p)(i));
      out.results.push_back(assemble_run_results(*parts[p].config, parts[p].options, plans[p].models, plans[p].units, std::move(runs)));
    }
  return out;
}

}  // namespace gpilqg::cli
