/// `gpilqg rollout --system NAME --policy POLICY.h5 --out LOG.csv|LOG.h5 [...]`: run a policy file on a
/// simulated world and log what a robot would log (docs/real-robot.md#without-hardware-gpilqg-rollout;
/// the log in the measurement format of docs/formats.md), so that the loop of plan, run, log, plan
/// again can be tried without hardware. The rollouts are policy_rollout.hpp's; this file reads the
/// options, checks them and reports.

#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/core/cost.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/plan_config.hpp"
#include "gpilqg/experiments/policy_file.hpp"
#include "gpilqg/experiments/policy_rollout.hpp"
#include "gpilqg/experiments/run_setup.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "world_options.hpp"

namespace gpilqg::cli {

namespace {

struct RolloutOptions {
  WorldOptions world;
  std::string policy;
  std::string out;
  std::string integrator = "rk4";
  int substeps = 10;
  int episodes = 1;
  std::vector<double> exploration;
  std::vector<double> observation_noise;
  std::vector<double> x0;
  std::string cost_config;
  std::uint64_t seed = 1;
  CLI::Option* integrator_option = nullptr;
  CLI::Option* substeps_option = nullptr;
};

/// The task cost of --cost: the [problem] of a `gpilqg plan` config, for the system and horizon of
/// the policy.
QuadraticCost task_cost(const std::string& cost_config, const SystemSignature& signature, int horizon) {
  const SolveConfig task = read_plan_config(cost_config).problem;
  const std::string mismatch = signature_mismatch(signature, system_signature(task.system));
  if (!mismatch.empty()) throw InputError(fmt::format("--cost {}: {}", cost_config, mismatch));
  if (task.horizon != horizon)
    throw InputError(fmt::format("--cost {}: [problem] horizon is {}; expected the policy's {}", cost_config,
                                 task.horizon, horizon));
  return make_solve_cost(task);
}

/// What the rollouts gave: the log written (or why not), the task costs and the episodes that
/// diverged. Returns the exit code.
int report_rollout(const RolloutOptions& o, const PolicyFile& policy, const PolicyRolloutResult& result) {
  const MeasurementSet& log = result.log;
  const std::vector<double>& costs = result.costs;
  if (log.episodes.empty()) {
    // A reported outcome, like a solve that does not converge: every episode's status, the file
    // left as it was (an episode of one sample holds no transition, the data format needs two), exit 1.
    std::cout << fmt::format("{} of {} episode(s) diverged at their first step: status diverged (a state not finite "
                             "or beyond |x| = {:g}); {} not written\n",
                             result.dropped, o.episodes, kDivergedStateMagnitude, o.out);
    std::cerr << fmt::format("warning: not written: every episode of the round-{} policy {} diverged at its first "
                             "step, so {} would hold no transition (try another --x0, world or policy)\n",
                             policy.round, o.policy, o.out);
    return kExitInternalFailure;
  }
  write_measurements(o.out, log);
  std::cout << fmt::format("wrote {}: {} episode(s) of the round-{} policy {} on {} ({}), {} rows, dt = {} s, seed {}\n",
                           o.out, log.episodes.size(), policy.round, o.policy,
                           o.world.world_file.empty() ? o.world.system : o.world.world_file, world_setting(o.world),
                           log.sample_count(), policy.dt, o.seed);
  if (!costs.empty()) {
    double mean = 0.0;
    for (const double c : costs) mean += c / static_cast<double>(costs.size());
    std::cout << fmt::format("task cost of the true trajectories ({}): mean {:.6g} over {} finite episode(s): {:.6g}\n",
                             o.cost_config, mean, costs.size(), fmt::join(costs, ", "));
  }
  if (result.overflowed > 0)
    std::cout << fmt::format("note: the task cost ({}) of {} finite episode(s) overflowed (not a finite number: the cost "
                             "weights are too large for the states reached); {}\n",
                             o.cost_config, result.overflowed, costs.empty() ? "no mean" : "the mean is over the others");
  if (result.diverged > 0)
    std::cout << fmt::format("note: {} episode(s) diverged; each is kept up to its last finite state{}\n",
                             result.diverged,
                             result.dropped > 0 ? fmt::format(" ({} with no finite step were left out)", result.dropped)
                                                : "");
  return kExitSuccess;
}

int run_rollout(const RolloutOptions& o) {
  std::vector<CommandInput> inputs = world_inputs(o.world);
  inputs.push_back({"--policy", o.policy});
  inputs.push_back({"--cost", o.cost_config});
  check_output_file_option("--out", o.out, {"rollout writes a log (CSV or HDF5)", kMeasurementExtensions}, inputs);
  const SystemSignature signature = system_signature(o.world.system);
  if (signature.controls.empty()) throw InputError("--system " + o.world.system + ": " + passive_system_refusal(o.world.system));
  const PolicyFile policy = read_policy_file(o.policy);
  if (policy.state_names != names_of(signature.states) || policy.control_names != names_of(signature.controls))
    throw InputError(fmt::format("--policy {}: its states [{}] and controls [{}] are not those of --system {} ([{}] and [{}])",
                                 o.policy, fmt::join(policy.state_names, ", "), fmt::join(policy.control_names, ", "),
                                 o.world.system, fmt::join(names_of(signature.states), ", "),
                                 fmt::join(names_of(signature.controls), ", ")));
  check_policy_system(policy, o.policy, o.world.system);
  const int n = static_cast<int>(signature.states.size());
  const int m = static_cast<int>(signature.controls.size());

  const DynamicsPtr dynamics = build_world(o.world, nullptr, "rollout");
  if (own_integrator(*dynamics) != nullptr && (o.integrator_option->count() || o.substeps_option->count()))
    throw InputError(fmt::format("--integrator/--substeps: {} steps with its own integrator; leave them out",
                                 o.world.system));
  const auto integrator = parse_integrator(o.integrator);
  if (!integrator) throw InputError("--integrator '" + o.integrator + "': expected 'euler' or 'rk4'");
  std::shared_ptr<const StepModel> world;
  try {
    world = make_step_model(dynamics, *integrator, policy.dt, o.substeps);
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("--policy {}: its dt = {} s does not fit the world: {}", o.policy, policy.dt, e.what()));
  }

  PolicyRolloutRequest request;
  request.policy = &policy;
  request.world = world.get();
  request.system = signature;
  request.x0 = o.x0.empty() ? Vector(policy.policy.x_bar.col(0))
                            : Vector(Eigen::Map<const Vector>(o.x0.data(), static_cast<Eigen::Index>(o.x0.size())));
  if (request.x0.size() != n) throw InputError(fmt::format("--x0: {} values; expected {} (one per state)", o.x0.size(), n));
  const int horizon = policy.policy.horizon();
  if (static_cast<double>(o.episodes) * (horizon + 1) > static_cast<double>(limits::kMaxSamples))
    throw InputError(fmt::format("--episodes {} of {} steps: more than {} samples (the sample limit)", o.episodes,
                                 horizon + 1, limits::kMaxSamples));
  request.episodes = o.episodes;
  request.exploration_std = per_quantity(o.exploration, m, "--exploration", Vector());
  request.observation_std = per_quantity(o.observation_noise, n, "--observation-noise", Vector());
  request.seed = o.seed;
  // The task's cost of each episode's true trajectory, when a plan config says what the task is.
  std::optional<QuadraticCost> cost;
  if (!o.cost_config.empty()) {
    cost.emplace(task_cost(o.cost_config, signature, horizon));
    request.task_cost = &*cost;
  }
  return report_rollout(o, policy, roll_out_policy(request));
}

}  // namespace

void add_rollout_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<RolloutOptions>();
  auto* cmd = app.add_subcommand("rollout", "Run a policy file on a simulated world and log it in the data format");
  add_world_options(*cmd, o->world);
  cmd->add_option("--policy", o->policy,
                  "Policy file of `gpilqg plan` (docs/formats.md#policy-file-gpilqg-plan---out-policyh5)")
      ->required();
  cmd->add_option("--out", o->out, "Log to write: .csv, or .h5 / .hdf5")->required();
  o->integrator_option = cmd->add_option("--integrator", o->integrator, "euler or rk4 (not for MuJoCo models)")
                             ->capture_default_str();
  o->substeps_option = cmd->add_option("--substeps", o->substeps, "Integrator sub-steps per policy step (not for "
                                                                  "MuJoCo models)")
                           ->capture_default_str()
                           ->check(integer_in(1, limits::kMaxSubsteps));
  cmd->add_option("--episodes", o->episodes, "Number of episodes")
      ->capture_default_str()
      ->check(integer_in(1, limits::kMaxRollouts));
  cmd->add_option("--exploration", o->exploration,
                  "Std of Gaussian noise added to each control: one value, or one per control (comma-separated)")
      ->delimiter(',');
  cmd->add_option("--observation-noise", o->observation_noise,
                  "Std of the noise on each measured state: one value, or one per state (comma-separated)")
      ->delimiter(',');
  cmd->add_option("--x0", o->x0, "Initial state, comma-separated (default: the policy's x_bar at t = 0)")
      ->delimiter(',')
      ->check(number_in(-kDivergedStateMagnitude, kDivergedStateMagnitude));
  cmd->add_option("--cost", o->cost_config, "A `gpilqg plan` config: print each episode's task cost (of its true "
                                            "states and applied controls)");
  cmd->add_option("--seed", o->seed, "Random seed; with `gpilqg plan --seed` the same seed gives `gpilqg run`'s draws")
      ->capture_default_str()
      ->check(integer_in(0, static_cast<long long>(limits::kMaxSeed)));
  cmd->callback([&action, o] { action = [o] { return run_rollout(*o); }; });
}

}  // namespace gpilqg::cli
