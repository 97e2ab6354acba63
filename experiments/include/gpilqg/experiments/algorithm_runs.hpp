#pragma once
/// @file algorithm_runs.hpp
/// The algorithms of `gpilqg run` on one task and one seed (docs/experiments.md):
///
///   ilqg_real   iLQG on the true (real-world) model: the reference optimum
///   ilqg_sim    iLQG on the simulator only
///   gp_ilqg     the paper's Algorithm 1: Robust-iLQG on simulator + GP residual, refitted on the
///               real-world rollouts of each iteration's policy (gp_ilqg_<backend> per GP backend)
///   pddp        PDDP trained at every iteration on exactly the data gp_ilqg had (the paper's protocol)
///   pddp_own    PDDP as published: random-control episodes first, then its own policy's rollouts
///
/// Every run has config.iterations + 1 iterations: iteration 0 is the policy before any data of this
/// task (for a transfer task, with the previous task's data), iteration k the policy after k rounds
/// of rollouts. A loop that converged (policy change below loop.policy_tolerance) stops collecting
/// and repeats its last iteration, marked `repeated`; so does a fixed-model algorithm.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/experiments/loop_diagnosis.hpp"
#include "gpilqg/experiments/task_actions.hpp"
#include "gpilqg/experiments/transition_data.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg {

struct IterationRecord {
  Plan plan;
  Evaluation evaluation;
  int data_rows = 0;            ///< transitions the plan's model was fitted on
  double fit_seconds = 0.0;
  double rollout_seconds = 0.0;  ///< data-collection rollouts after this iteration's plan
  double policy_change = -1.0;   ///< AffinePolicy::distance to the previous iteration (-1: none)
  std::vector<Vector> hyperparameters;  ///< per state output: [log l (n+m); log sf; log sn] (empty: no GP)
  Vector noise_floor;  ///< per state output: the lower bound on sn (gp/noise_floor.hpp; empty: no GP)
  bool repeated = false;        ///< a copy of the previous iteration (converged or fixed model)
  std::string start;            ///< gp_ilqg: where the solve started (ReferencePlans::start_name; empty: not said)
};

struct AlgorithmRun {
  std::string name;
  std::vector<IterationRecord> iterations;
  int converged_at = -1;  ///< first iteration whose policy change fell below the tolerance (-1: never)
  TransitionData data;    ///< everything it collected, including data carried over from an earlier task
  std::shared_ptr<const StepModel> final_model;  ///< the last plan's model (GP-ILQG: the residual model)
  /// gp_ilqg with [diagnosis] after_round: the diagnosis of its data, or the model its previous task
  /// adopted (loop_diagnosis.hpp); empty before the diagnosis and without one.
  std::optional<LoopDiagnosis> diagnosis;
};

/// Where each algorithm's progress is kept, so that an interrupted run can continue from its last
/// completed iteration (run_checkpoint.hpp). Every algorithm asks `restore` before it starts and calls
/// `save` after each completed iteration with everything it has so far; a restored run continues
/// exactly as if it had never stopped (its random streams depend on (seed, task, iteration) only).
class RunJournal {
 public:
  virtual ~RunJournal() = default;
  /// What `save` last received for algorithm `name` on this task and seed, or nothing.
  virtual std::optional<AlgorithmRun> restore(const TaskContext& context, std::uint64_t seed,
                                              const std::string& name) const = 0;
  /// Keeps `run` (its completed iterations, data and final model). May throw to stop the run.
  virtual void save(const TaskContext& context, std::uint64_t seed, const AlgorithmRun& run) = 0;
};

/// A fixed-model run restored from a journal gets its model back (a journal keeps no fixed model).
void attach_fixed_model(AlgorithmRun& run, const std::shared_ptr<const StepModel>& model);

/// ilqg_real (world) or ilqg_sim (simulator): one iLQG plan, evaluated once, repeated.
AlgorithmRun run_fixed_model(const TaskContext& context, const std::string& name,
                             std::shared_ptr<const StepModel> model, std::uint64_t seed);

/// Algorithm 1 with `backend`, starting from `initial` data (an earlier task's, or empty). The plans use
/// the config's simulator, or the diagnosed model from the round after [diagnosis] after_round when
/// the diagnosis explained the data (loop_diagnosis.hpp); `inherited`, the diagnosis of the previous
/// task's run, is the model from iteration 0 on when it adopted one.
AlgorithmRun run_gp_ilqg(const TaskContext& context, const std::string& name, const gp::GpBackend& backend,
                         TransitionData initial, std::uint64_t seed,
                         const std::optional<LoopDiagnosis>& inherited = std::nullopt);

/// The solver options of PDDP's plans: [solver] with [pddp] max_iterations as the only cap. No wall-time
/// limit: DdpOptions' default 60 s used to stop the quadrotor's PDDP solves after 2 to 6 of their 10
/// iterations, at a point that depended on the machine's load (issue 18).
DdpOptions pddp_solver_options(const RunConfig& config);

/// PDDP on the data `source` had at each of its iterations (no rollouts of its own).
AlgorithmRun run_pddp_on_data_of(const TaskContext& context, const AlgorithmRun& source, std::uint64_t seed);

/// PDDP collecting its own data: when `initial` is empty, config.pddp_own_initial_rollouts random
/// episodes first.
AlgorithmRun run_pddp_own(const TaskContext& context, TransitionData initial, std::uint64_t seed);

}  // namespace gpilqg
