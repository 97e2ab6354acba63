#pragma once
/// @file run_setup.hpp
/// What every algorithm of `gpilqg run` shares for one task: the real world, the simulator, the task
/// cost and the random streams. The world is the system with the paper's real-world preset (a 30%
/// longer pole, a 40% heavier quadrotor) with multiplicative process noise; the simulator is the
/// simulator preset with the same noise model (the paper assumes F known) and the same integrator,
/// so the only model error is the physical one.

#include <cstdint>
#include <memory>
#include <random>
#include <string>

#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/step_model.hpp"
#include "gpilqg/experiments/run_config.hpp"

namespace gpilqg {

struct RunModels {
  std::shared_ptr<const StepModel> world;      ///< real-world preset: where rollouts happen, ilqg_real's model
  std::shared_ptr<const StepModel> simulator;  ///< simulator preset: ilqg_sim's model, GP-ILQG's mean function
};

/// Builds both models from [system] and [noise]. Throws std::invalid_argument on inconsistent sizes.
RunModels make_run_models(const RunConfig& config);

/// The task's quadratic cost: regulation to `goal`, or tracking of the straight line x0 -> goal when
/// task.track_line (the quadrotor tasks), with running cost dt (0.5 e'Qe + 0.5 u'Ru), terminal
/// 0.5 e'Qf e.
QuadraticCost make_task_cost(const RunConfig& config, const RunTask& task);

/// Independent random streams of a run, one per (seed, task, purpose, index...): every draw of a
/// seeded run is reproducible, and the evaluation rollouts of all algorithms share their noise
/// (common random numbers), so their costs differ by their policies only.
enum class RandomStream : std::uint64_t {
  Evaluation = 1,   ///< index: evaluation rollout e (the same for every algorithm and iteration)
  DataRollout = 2,  ///< index: algorithm, iteration, rollout
  GpFit = 3,        ///< index: algorithm, iteration
  RandomData = 4,   ///< index: algorithm, rollout (pddp_own's initial random episodes)
  Diagnosis = 5,    ///< index: algorithm, round (the GP fits of the diagnosis inside the loop)
};
std::mt19937_64 make_rng(std::uint64_t seed, int task, RandomStream stream, std::initializer_list<std::uint64_t> index);
/// A 64-bit seed drawn from the same streams (for APIs that take a seed, e.g. FitOptions::seed).
std::uint64_t derive_seed(std::uint64_t seed, int task, RandomStream stream, std::initializer_list<std::uint64_t> index);

/// A stable number for an algorithm's name (FNV-1a), so that its random streams do not depend on the
/// order in which algorithms run.
std::uint64_t stream_id(const std::string& algorithm);

/// The streams of one round of Algorithm 1, named once so that `gpilqg run` and a scripted loop of
/// `gpilqg plan` and `gpilqg rollout` with the same seed draw the same numbers:
///  - the seed of the GP fit when the algorithm has `rows` transitions;
///  - the stream of data rollout `rollout` after the plan of round `round`.
/// `gpilqg plan --seed S` and `gpilqg rollout --seed S` are task 0 of algorithm "gp_ilqg".
std::uint64_t gp_fit_seed(std::uint64_t seed, int task, const std::string& algorithm, int rows);
std::mt19937_64 data_rollout_rng(std::uint64_t seed, int task, const std::string& algorithm, int round, int rollout);

}  // namespace gpilqg
