/// `gpilqg rollout --system NAME --policy POLICY.h5 --out LOG.csv|LOG.h5 [...]`: run a policy file on a
/// simulated world and log what a robot would log (docs/real-robot.md#without-hardware-gpilqg-rollout),
/// so that the loop of plan, run, log, plan again can be tried without hardware.

#include <cmath>
#include <iostream>
#include <memory>
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
#include "gpilqg/experiments/run_setup.hpp"
#include "gpilqg/experiments/task_actions.hpp"
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

/// One episode of the log: the measured states (what the controller saw) and the applied controls,
/// one row per step up to the last finite state; the last row repeats the last control (no transition
/// starts there).
Episode episode_of(const RealRollout& r, int id, double dt) {
  const int rows = r.steps_completed + 1;
  Episode e;
  e.id = id;
  e.t.resize(rows);
  for (int j = 0; j < rows; ++j) e.t(j) = dt * j;
  e.x = r.measured.leftCols(rows).transpose();
  e.u.resize(rows, r.truth.u.rows());
  e.u.topRows(rows - 1) = r.truth.u.leftCols(rows - 1).transpose();
  e.u.row(rows - 1) = e.u.row(std::max(0, rows - 2));
  return e;
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

  WorldRollout setup;
  setup.world = world.get();
  setup.x0 = o.x0.empty() ? Vector(policy.policy.x_bar.col(0)) : Vector(Eigen::Map<const Vector>(o.x0.data(), static_cast<Eigen::Index>(o.x0.size())));
  if (setup.x0.size() != n) throw InputError(fmt::format("--x0: {} values; expected {} (one per state)", o.x0.size(), n));
  setup.horizon = policy.policy.horizon();
  if (static_cast<double>(o.episodes) * (setup.horizon + 1) > static_cast<double>(limits::kMaxSamples))
    throw InputError(fmt::format("--episodes {} of {} steps: more than {} samples (the sample limit)", o.episodes,
                                 setup.horizon + 1, limits::kMaxSamples));
  setup.exploration_std = per_quantity(o.exploration, m, "--exploration", Vector());
  setup.observation_std = per_quantity(o.observation_noise, n, "--observation-noise", Vector());
  setup.u_min = policy.policy.u_min;
  setup.u_max = policy.policy.u_max;
  const AffinePolicy& law = policy.policy;
  const Controller act = [&law](int t, const VectorCRef& x, VectorRef u) { law.control(t, x, u); };

  // The task's cost of each episode's true trajectory, when a plan config says what the task is.
  std::unique_ptr<QuadraticCost> cost;
  if (!o.cost_config.empty()) {
    const SolveConfig task = read_plan_config(o.cost_config).problem;
    const std::string mismatch = signature_mismatch(signature, system_signature(task.system));
    if (!mismatch.empty()) throw InputError(fmt::format("--cost {}: {}", o.cost_config, mismatch));
    if (task.horizon != setup.horizon)
      throw InputError(fmt::format("--cost {}: [problem] horizon is {}; expected the policy's {}", o.cost_config,
                                   task.horizon, setup.horizon));
    cost = std::make_unique<QuadraticCost>(make_solve_cost(task));
  }
  std::vector<double> costs;

  MeasurementSet log;
  log.system = signature;
  int diverged = 0, dropped = 0, overflowed = 0;
  for (int r = 0; r < o.episodes; ++r) {
    // The stream of data rollout r after the plan of this round: what `gpilqg run` draws (run_setup.hpp).
    auto rng = data_rollout_rng(o.seed, 0, "gp_ilqg", policy.round, r);
    const RealRollout rollout = roll_out(setup, act, rng);
    if (!rollout.finite) ++diverged;
    if (cost && rollout.finite) {
      const double value = trajectory_cost(*cost, rollout.truth);
      if (std::isfinite(value)) costs.push_back(value);
      else ++overflowed;  // states within the divergence bound, the weighted sum beyond a double
    }
    if (rollout.steps_completed == 0) {
      ++dropped;
      continue;
    }
    log.episodes.push_back(episode_of(rollout, r, policy.dt));
  }
  if (log.episodes.empty()) {
    // A reported outcome, like a solve that does not converge: every episode's status, the file
    // left as it was (an episode of one sample holds no transition, the data format needs two), exit 1.
    std::cout << fmt::format("{} of {} episode(s) diverged at their first step: status diverged (a state not finite "
                             "or beyond |x| = {:g}); {} not written\n",
                             dropped, o.episodes, kDivergedStateMagnitude, o.out);
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
  if (overflowed > 0)
    std::cout << fmt::format("note: the task cost ({}) of {} finite episode(s) overflowed (not a finite number: the cost "
                             "weights are too large for the states reached); {}\n",
                             o.cost_config, overflowed, costs.empty() ? "no mean" : "the mean is over the others");
  if (diverged > 0)
    std::cout << fmt::format("note: {} episode(s) diverged; each is kept up to its last finite state{}\n", diverged,
                             dropped > 0 ? fmt::format(" ({} with no finite step were left out)", dropped) : "");
  return kExitSuccess;
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
