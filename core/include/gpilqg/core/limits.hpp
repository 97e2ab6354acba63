#pragma once
/// @file limits.hpp
/// The documented limits of every size a user can ask for (docs/reliability.md, "Limits"). A value
/// beyond one is bad input, reported with the limit's value before anything is allocated, instead
/// of a run that grows to gigabytes. Each limit is far above what the paper's experiments and any
/// realistic robot study use, and low enough that the memory it implies fits one workstation; the
/// memory estimate of a trajectory optimisation is checked against kMemoryBudgetBytes as well.

#include <cstdint>
#include <optional>
#include <string>

namespace gpilqg::limits {

/// Time steps of one trajectory (a task's or problem's horizon, an MPC horizon).
inline constexpr long kMaxHorizon = 1'000'000;
/// Integrator sub-steps per control period.
inline constexpr long kMaxSubsteps = 10'000;
/// GP-ILQG iterations of one task (loop.iterations, `run --iterations`).
inline constexpr long kMaxLoopIterations = 1'000;
/// Iterations of one trajectory-optimisation solve (solver.max_iterations, pddp.max_iterations, MPC).
inline constexpr long kMaxSolverIterations = 100'000;
/// Seeds of one `gpilqg run` (their list is one HDF5 attribute of the result and its checkpoint).
inline constexpr long kMaxSeeds = 1'000;
/// The largest seed (seeds are stored exactly as doubles by HDF5 readers of the results: 2^53).
inline constexpr std::uint64_t kMaxSeed = std::uint64_t{1} << 53;
/// Rollouts per iteration (loop.rollouts, loop.evaluation_rollouts) and episodes of a rollout.
inline constexpr long kMaxRollouts = 100'000;
/// Samples a command may generate: episodes x steps of `simulate` and `rollout`.
inline constexpr long kMaxSamples = 10'000'000;
/// Random restarts of a GP fit.
inline constexpr long kMaxRestarts = 1'000;
/// Likelihood evaluations per start of a GP fit.
inline constexpr long kMaxEvaluations = 1'000'000;
/// Training points of the exact GP per output (its N x N matrices: 3.2 GB at this size).
inline constexpr long kMaxExactPoints = 20'000;
/// Inducing points of FITC (its N x M and M x M matrices).
inline constexpr long kMaxInducing = 10'000;
/// Spectral frequencies of the sparse-spectrum GP (its 2M x 2M matrices: 512 MB at this size).
inline constexpr long kMaxFrequencies = 4'096;
/// Neighbours per point of the compact-support GP's sparse kernel matrix.
inline constexpr long kMaxNeighbours = 10'000;
/// Effects a model file declares ([[user_effects]]): each is a candidate the diagnosis fits.
inline constexpr long kMaxUserEffects = 1'000;
/// Terms of one declared effect (its parameters, fitted together).
inline constexpr long kMaxBasisTerms = 100;
/// Worker threads of one command.
inline constexpr long kMaxThreads = 1'024;
/// The largest cost weight (each diagonal entry of Q, R and Qf of a config), chosen so that the cost
/// of any trajectory within the divergence bound is a finite double. A state or goal entry is within
/// |x| <= 1e12 (kDivergedStateMagnitude, control/rollout.hpp), an initial control likewise, so an
/// error e = x - goal has |e_i| <= 2e12 and e_i^2 <= 4e24. One weighted square is then at most
/// 1e150 * 4e24 = 4e174; a stage cost sums n + m of them times dt, a trajectory T <= kMaxHorizon =
/// 1e6 stages, an evaluation a mean of rollouts: the total stays below the largest double (1.8e308)
/// while n * T * dt < 1e133, a margin no dimension or step of a real problem approaches. A weight of
/// 1e308 instead makes a state of 1e1 overflow to inf, which the solver would see as divergence.
inline constexpr double kMaxCostWeight = 1e150;
/// The largest control bound a model may give (a URDF joint's effort limit): beyond the divergence
/// bound of controls (|u| <= 1e12, kDivergedStateMagnitude) a bound bounds nothing, and twice it
/// overflows the excitation of `simulate` (1e308).
inline constexpr double kMaxControlBound = 1e12;
/// Memory a command may plan to use for the arrays whose size the user controls (horizons x state
/// dimensions, GP matrices); `profile --memory-budget-gb` sets its own.
inline constexpr double kMemoryBudgetBytes = 8.0 * (1ull << 30);

/// Bytes a trajectory optimisation over `horizon` steps with n states and m controls keeps per
/// solve: the nominal and candidate trajectories, the model's Jacobians f_x, f_u, the cost's
/// derivatives, the gains k, K and the value function's V_x, V_xx at every step, counted with a
/// factor 2 for the solver's scratch copies. In belief space (PDDP) the state is the mean and the
/// covariance, n + n^2 numbers.
double trajectory_bytes(long horizon, long n, long m, bool belief_space);

/// Why a trajectory optimisation of that size does not fit kMemoryBudgetBytes, or nullopt:
/// "needs about 12.3 GB for its per-step matrices, more than the budget of 8 GB".
std::optional<std::string> trajectory_memory_problem(long horizon, long n, long m, bool belief_space);

}  // namespace gpilqg::limits
