#pragma once
/// @file reference_plans.hpp
/// The plans a plan on a changed model must not lose to (docs/solvers.md, "Plans that never lose").
///
/// A planner whose model is richer than the simulator it started from (a diagnosed model that `run`'s
/// loop or `plan --diagnose` adopted, a model file declared as [system] model) may end in a worse local
/// optimum than a plan on the simpler model: iLQG on a model with smoothed Coulomb friction, for
/// example, can stop where the plan of the frictionless simulator, replayed with its feedback, costs
/// less on that very model. So the simpler models' plans are kept as further starts of every solve
/// on the richer one (plan_with_ddp's plans_to_keep), and the best by the richer model's expected cost
/// wins.

#include <memory>
#include <string>
#include <vector>

#include "gpilqg/control/policy.hpp"
#include "gpilqg/experiments/loop_diagnosis.hpp"
#include "gpilqg/experiments/task_actions.hpp"

namespace gpilqg {

/// A model simpler than the one planned on, and what it is called in reports.
struct SimplerModel {
  std::string name;  ///< "the system's preset 'sim' alone" or "the config's simulator"
  std::shared_ptr<const StepModel> model;
};

/// The simpler models of `planned_on`, in this order: the system at its preset alone
/// (ModelSpec::describe empty), then `config.simulator`; each one that is not `planned_on` and not a
/// model before it (same model file text), built like the config's simulator (its integrator, dt and
/// sub-steps, with `noise`).
std::vector<SimplerModel> simpler_models(const LoopModel& config, const ActuatorNoise& noise, const ModelSpec& planned_on);

/// The plans a solve keeps as further starts (plan_with_ddp's plans_to_keep) and what each is called.
struct ReferencePlans {
  std::vector<std::string> names;  ///< "the plan on " + a simpler model's name, "the previous round's policy"
  std::vector<AffinePolicy> policies;
  /// Keeps `policy` as a further start, called `name` in reports.
  void keep(std::string name, AffinePolicy policy);
  /// What Plan::start `start` means: "the usual start" (0) or names[start - 1].
  std::string start_name(int start) const;
};

/// What Plan::start 0 is called: u_init, or the previous round's controls open loop.
inline constexpr const char* kUsualStart = "the usual start";

/// What a new round's plan keeps of the previous round (a GP refitted on more data is a changed model
/// too): its policy, replayed with its feedback on the new model, beside the usual start (the previous
/// round's controls, open loop).
inline constexpr const char* kPreviousRoundsPolicy = "the previous round's policy";

/// `variant` (from task.u_init, the task's solver options) on each simpler model of `planned_on`:
/// what a plan on `planned_on` keeps as further starts. Empty when `planned_on` is the preset itself.
ReferencePlans reference_plans(const DdpTask& task, DdpVariant variant, const LoopModel& config,
                               const ActuatorNoise& noise, const ModelSpec& planned_on);

}  // namespace gpilqg
