#include "gpilqg/experiments/algorithm_runs.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/control/belief_space.hpp"
#include "gpilqg/experiments/gp_ilqg_round.hpp"
#include "gpilqg/experiments/reference_plans.hpp"
#include "gpilqg/gp/gp_belief_dynamics.hpp"
#include "gpilqg/gp/residual_model.hpp"

#include "elapsed_seconds.hpp"

namespace gpilqg {
namespace {

void report(const TaskContext& c, const std::string& name, int k, const IterationRecord& r) {
  if (!c.progress) return;
  c.progress(fmt::format("{} {} iteration {}/{}: cost {:.4g}{} (data {}, fit {:.1f} s, solve {:.1f} s, rollouts {:.1f} s, "
                         "evaluation {:.1f} s{}{})",
                         c.task.name, name, k, c.config.iterations, r.evaluation.mean_cost,
                         r.evaluation.diverged ? fmt::format(", {} diverged", r.evaluation.diverged) : "", r.data_rows,
                         r.fit_seconds, r.plan.solve_seconds, r.rollout_seconds, r.evaluation.seconds,
                         r.policy_change >= 0.0 ? fmt::format(", policy change {:.3g}", r.policy_change) : "",
                         r.start.empty() || r.start == kUsualStart ? "" : ", solve started from " + r.start));
}

/// Plans from data; fills the record's fit time and hyperparameters and may keep the plan's model.
/// `run` is the run so far (its diagnosis decides the simulator).
using DataPlanner =
    std::function<Plan(const TransitionData& data, const Plan* previous, IterationRecord& record, const AlgorithmRun& run)>;
/// Called after the rollouts of round k have been added to run.data.
using AfterRollouts = std::function<void(AlgorithmRun& run, int k)>;

/// The loop every data-driven algorithm shares (Algorithm 1's structure): plan from the data,
/// evaluate, stop when the policy no longer changes, else roll the policy out config.rollouts times
/// with exploration and add what was measured. With `borrowed`, the data of iteration k is what that
/// run had at its iteration k, and nothing is collected.
AlgorithmRun learning_loop(const TaskContext& c, const std::string& name, TransitionData initial, std::uint64_t seed,
                           const DataPlanner& planner, const AlgorithmRun* borrowed = nullptr,
                           const AfterRollouts& after_rollouts = {},
                           const std::optional<LoopDiagnosis>& inherited = std::nullopt) {
  std::optional<AlgorithmRun> restored = c.journal != nullptr ? c.journal->restore(c, seed, name) : std::nullopt;
  AlgorithmRun run;
  if (restored) {
    run = std::move(*restored);
  } else {
    run.name = name;
    run.data = std::move(initial);
    run.diagnosis = inherited;
  }
  const int K = c.config.iterations;
  bool stopped = run.converged_at >= 0 && borrowed == nullptr;
  for (int k = static_cast<int>(run.iterations.size()); k <= K; ++k) {
    const IterationRecord* previous = k > 0 ? &run.iterations.back() : nullptr;
    const TransitionData data =
        borrowed != nullptr ? borrowed->data.head(borrowed->iterations.at(static_cast<std::size_t>(k)).data_rows)
                            : run.data;
    if (stopped || (borrowed != nullptr && previous != nullptr && data.size() == previous->data_rows)) {
      IterationRecord copy = *previous;
      copy.repeated = true;
      copy.rollout_seconds = copy.fit_seconds = 0.0;
      copy.plan.solve_seconds = copy.evaluation.seconds = 0.0;
      run.iterations.push_back(std::move(copy));
    } else {
      IterationRecord record;
      record.data_rows = data.size();
      record.plan = planner(data, previous != nullptr ? &previous->plan : nullptr, record, run);
      record.evaluation = evaluate(c, record.plan, seed);
      if (previous != nullptr) {
        record.policy_change = record.plan.policy.distance(previous->plan.policy);
        if (record.policy_change <= c.config.policy_tolerance && run.converged_at < 0) {
          run.converged_at = k;
          stopped = borrowed == nullptr;  // a borrowing run follows its source's data to the end
        }
      }
      if (borrowed == nullptr && !stopped && k < K) {
        const auto start = std::chrono::steady_clock::now();
        for (int r = 0; r < c.config.rollouts; ++r) {
          auto rng = data_rollout_rng(seed, c.task_index, name, k, r);
          run.data.append(roll_out(c, record.plan, c.config.exploration_std, rng), k);
        }
        record.rollout_seconds = seconds_since(start);
        if (after_rollouts) after_rollouts(run, k);
      }
      report(c, name, k, record);
      run.final_model = record.plan.model;
      run.iterations.push_back(std::move(record));
    }
    if (c.journal != nullptr) c.journal->save(c, seed, run);
  }
  return run;
}

Matrix warm_start(const Plan* previous) { return previous != nullptr ? previous->policy.u_bar : Matrix(); }

gp::FitOptions fit_options(const TaskContext& c, std::uint64_t seed, const std::string& name, int data_rows) {
  gp::FitOptions options;
  options.restarts = c.config.gp.restarts;
  options.max_evaluations = c.config.gp.max_evaluations;
  options.seed = gp_fit_seed(seed, c.task_index, name, data_rows);
  return options;
}

}  // namespace

void attach_fixed_model(AlgorithmRun& run, const std::shared_ptr<const StepModel>& model) {
  for (auto& record : run.iterations) record.plan.model = model;
  run.final_model = model;
}

AlgorithmRun run_fixed_model(const TaskContext& c, const std::string& name, std::shared_ptr<const StepModel> model,
                             std::uint64_t seed) {
  if (auto restored = c.journal != nullptr ? c.journal->restore(c, seed, name) : std::nullopt) {
    attach_fixed_model(*restored, model);
    return std::move(*restored);
  }
  AlgorithmRun run;
  run.name = name;
  IterationRecord record;
  record.plan = plan_with_ddp(c, std::move(model), DdpVariant::ILQG, Matrix());
  record.evaluation = evaluate(c, record.plan, seed);
  report(c, name, 0, record);
  run.final_model = record.plan.model;
  run.iterations.push_back(record);
  record.repeated = true;
  record.plan.solve_seconds = record.evaluation.seconds = 0.0;
  for (int k = 1; k <= c.config.iterations; ++k) run.iterations.push_back(record);
  if (c.journal != nullptr) c.journal->save(c, seed, run);
  return run;
}

AlgorithmRun run_gp_ilqg(const TaskContext& c, const std::string& name, const gp::GpBackend& backend,
                         TransitionData initial, std::uint64_t seed, const std::optional<LoopDiagnosis>& inherited) {
  const DdpTask task = ddp_task(c);
  std::shared_ptr<const StepModel> diagnosed;  // built once, when the run adopts a diagnosed model
  const auto simulator_of = [&](const AlgorithmRun& run) {
    if (!run.diagnosis || !run.diagnosis->adopted) return c.models.simulator;
    if (!diagnosed) diagnosed = planning_simulator(loop_model(c.config), c.config.noise, c.models.simulator, run.diagnosis);
    return diagnosed;
  };
  std::map<bool, ReferencePlans> kept;  // reference_plans, by whether a diagnosed model is planned on
  // The plans a round keeps as further starts: the simpler models' plans, then the previous round's policy.
  const auto plans_to_keep = [&](const AlgorithmRun& run, const Plan* previous) {
    const bool on_diagnosed = run.diagnosis && run.diagnosis->adopted;
    auto found = kept.find(on_diagnosed);
    if (found == kept.end())
      found = kept.emplace(on_diagnosed, reference_plans(task, DdpVariant::ILQG, loop_model(c.config), c.config.noise,
                                                          on_diagnosed ? run.diagnosis->model : c.config.simulator))
                  .first;
    ReferencePlans plans = found->second;
    if (previous != nullptr) plans.keep(kPreviousRoundsPolicy, previous->policy);
    return plans;
  };
  const DataPlanner planner = [&](const TransitionData& data, const Plan* previous, IterationRecord& record,
                                  const AlgorithmRun& run) {
    const std::shared_ptr<const StepModel> simulator = simulator_of(run);
    GpRoundInputs inputs;
    inputs.data = &data;
    inputs.backend = &backend;
    // The previous iteration's GP (warm start, re-sample rule) is the model its plan was made on; a GP
    // of another mean function (before the diagnosed model was adopted) learned another residual.
    const bool new_mean = static_cast<int>(run.iterations.size()) == diagnosed_from(run.diagnosis);
    inputs.previous_model = previous != nullptr && !new_mean
                                ? std::dynamic_pointer_cast<const gp::ResidualModel>(previous->model)
                                : nullptr;
    inputs.previous_u_bar = warm_start(previous);
    inputs.fit = fit_options(c, seed, name, data.size());
    inputs.variant = c.config.gp_variant;
    inputs.threads = c.threads;
    inputs.observation_std = c.config.observation_std;
    inputs.known_noise = c.config.gp.known_noise;
    const ReferencePlans plans = plans_to_keep(run, previous);
    inputs.plans_to_keep = plans.policies;
    GpRound round = plan_gp_ilqg_round(task, simulator, inputs);
    record.start = plans.start_name(round.plan.start);
    record.fit_seconds = round.fit_seconds;
    record.hyperparameters = std::move(round.hyperparameters);
    record.noise_floor = std::move(round.noise_floor);
    return std::move(round.plan);
  };
  const AfterRollouts diagnose = [&](AlgorithmRun& run, int k) {
    if (k != c.config.diagnose_after || run.diagnosis) return;
    const std::string prefix = fmt::format("{} {} round {}: diagnosis", c.task.name, name, k);
    if (c.progress) c.progress(fmt::format("{} of {} transitions", prefix, run.data.size()));
    const auto stream = derive_seed(seed, c.task_index, RandomStream::Diagnosis, {stream_id(name), static_cast<std::uint64_t>(k)});
    run.diagnosis = diagnose_loop_data(loop_model(c.config), run.data, k, stream);
    const LoopDiagnosis& d = *run.diagnosis;
    if (c.progress)
      c.progress(fmt::format("{}: {} in {:.1f} s; {}", prefix, d.verdict, d.seconds,
                             d.adopted ? fmt::format("the simulator from round {} on: {}", k + 1, fmt::join(d.changes, "; "))
                                       : "the simulator stays: " + d.reason));
  };
  const bool adopted = inherited && inherited->adopted;
  std::optional<LoopDiagnosis> carried;
  if (adopted) {
    carried = inherited;
    carried->round = -1;
  }
  return learning_loop(c, name, std::move(initial), seed, planner, nullptr,
                       c.config.diagnose_after >= 0 && !adopted ? diagnose : AfterRollouts{}, carried);
}

namespace {

/// PDDP's plan from data: n GPs on z = [x; u] -> x' - x (no simulator), moment matching, DDP over the
/// belief from N(x0, diag(observation_std^2)); the policy acts on measured states (belief_space.hpp).
DataPlanner pddp_planner(const TaskContext& c, const std::string& name, std::uint64_t seed) {
  return [&c, name, seed](const TransitionData& data, const Plan* previous, IterationRecord& record, const AlgorithmRun&) {
    if (data.size() == 0) return open_loop_plan(c);  // no data, no model: PDDP's initial controls
    const auto start = std::chrono::steady_clock::now();
    const int n = static_cast<int>(data.x.cols()), m = static_cast<int>(data.u.cols());
    Matrix inputs(data.size(), n + m);
    inputs << data.x, data.u;
    const Matrix increments = data.x_next - data.x;
    const auto backend = gp::make_backend(c.config.pddp_backend, c.config.gp.backend_settings);
    const auto dynamics = gp::GpBeliefDynamics::fit(n, m, c.config.dt, inputs, increments, *backend,
                                                    fit_options(c, seed, name, data.size()), nullptr, c.threads);
    record.fit_seconds = seconds_since(start);

    PddpProblem problem;
    problem.model = &dynamics;
    problem.cost = &c.cost;
    problem.x0 = c.task.x0;
    problem.Sigma0 = c.config.observation_std.array().square().matrix().asDiagonal();
    problem.horizon = c.task.horizon;
    problem.u_min = c.config.u_min;
    problem.u_max = c.config.u_max;
    const DdpOptions options = pddp_solver_options(c.config);
    const Matrix u_start = previous != nullptr ? previous->policy.u_bar : Matrix(c.config.u_init.replicate(1, c.task.horizon));
    const auto solve_start = std::chrono::steady_clock::now();
    PddpResult result = solve_pddp(problem, u_start, options);
    Plan plan;
    plan.solve_seconds = seconds_since(solve_start);
    plan.policy = std::move(result.state_policy);
    plan.predicted_cost = result.belief.expected_cost;
    plan.summary = std::move(result.belief.summary);
    plan.variant = DdpVariant::ILQR;
    Trajectory reached;
    reached.x = plan.policy.x_bar;
    reached.u = plan.policy.u_bar;
    score_diverged_solve(plan, c.cost, reached);
    return plan;  // no StepModel: PDDP's policy acts without MPC
  };
}

}  // namespace

DdpOptions pddp_solver_options(const RunConfig& config) {
  DdpOptions options = config.solver;
  options.max_iterations = config.pddp_max_iterations;  // with [solver]'s no wall-time limit (run_config.hpp)
  return options;
}

AlgorithmRun run_pddp_on_data_of(const TaskContext& c, const AlgorithmRun& source, std::uint64_t seed) {
  return learning_loop(c, "pddp", TransitionData{}, seed, pddp_planner(c, "pddp", seed), &source);
}

AlgorithmRun run_pddp_own(const TaskContext& c, TransitionData initial, std::uint64_t seed) {
  const std::string name = "pddp_own";
  if (initial.size() == 0) {
    for (int r = 0; r < c.config.pddp_own_initial_rollouts; ++r) {
      auto rng = make_rng(seed, c.task_index, RandomStream::RandomData, {stream_id(name), static_cast<std::uint64_t>(r)});
      initial.append(random_rollout(c, c.config.pddp_own_amplitude, rng), -1);
    }
  }
  return learning_loop(c, name, std::move(initial), seed, pddp_planner(c, name, seed));
}

}  // namespace gpilqg
