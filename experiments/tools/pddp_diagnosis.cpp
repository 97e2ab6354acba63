// Diagnosis of one PDDP plan of `gpilqg run` (docs/experiments.md, Quadrotor): fits PDDP's GPs to the first
// `rows` transitions of a CSV (x, u, x' - x per row, as /<task>/data of a run result), solves PDDP as
// pddp_planner does, and reports what the plan predicts, what it does on the GP mean, the simulator
// and the real world (open loop and with its feedback, with and without noise), the GP's one-step
// error along those trajectories and the belief's covariance growth.
//
//   pddp_diagnosis SYSTEM DATA.csv ROWS MAX_ITERATIONS [TASK_INDEX] [SEED] [MAX_SECONDS]
//
// DATA.csv may be "synthetic": ROWS real-world transitions scattered around ilqg_real's plan.
// Variants (environment): DIAG_U_INIT (initial thrust per rotor), DIAG_U_MIN / DIAG_U_MAX (limits),
// DIAG_LAMBDA0 (initial regularisation), DIAG_REG ("control" or "value"), DIAG_START_REFERENCE=1
// (start from ilqg_real's controls), DIAG_MIN_NOISE (floor on every GP's noise std).
// Not part of the suite; built on request (target gpilqg_pddp_diagnosis). Results: docs/experiments.md.

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gpilqg/control/belief_space.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/control/trajectory.hpp"
#include "gpilqg/core/belief.hpp"
#include "gpilqg/experiments/run_config.hpp"
#include "gpilqg/experiments/run_setup.hpp"
#include "gpilqg/experiments/task_actions.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/gp_belief_dynamics.hpp"

using namespace gpilqg;

namespace {

Matrix read_csv(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  Matrix m(rows.size(), rows.empty() ? 0 : rows[0].size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < rows[i].size(); ++j) m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = rows[i][j];
  return m;
}

void print_state_rows(const char* label, const Matrix& x, const Matrix* u) {
  std::printf("%s (t: px py pz | vx vy vz | rx ry rz | wx wy wz || u)\n", label);
  for (int t = 0; t < x.cols(); t += (t < 10 ? 1 : 5)) {
    std::printf("  %2d:", t);
    for (int i = 0; i < x.rows(); ++i) std::printf(" %8.3f", x(i, t));
    if (u && t < u->cols()) {
      std::printf(" ||");
      for (int j = 0; j < u->rows(); ++j) std::printf(" %7.3f", (*u)(j, t));
    }
    std::printf("\n");
  }
}

/// GP mean one-step prediction at (x, u): mu' of the belief step from a point belief.
Vector gp_mean_step(const gp::GpBeliefDynamics& gp, const Vector& x, const Vector& u) {
  const int n = static_cast<int>(x.size());
  Vector v(belief_dim(n)), v_next(belief_dim(n));
  pack_belief(x, Matrix::Zero(n, n), v);
  gp.propagate(v, u, v_next);
  return v_next.head(n);
}

/// RMS over t of the GP's one-step error against `truth` along (x_t, u_t), per state.
Vector one_step_error(const gp::GpBeliefDynamics& gp, const StepModel& truth, const Matrix& x, const Matrix& u,
                      int steps) {
  const int n = static_cast<int>(x.rows());
  Vector sq = Vector::Zero(n);
  for (int t = 0; t < steps; ++t) {
    const Vector e = gp_mean_step(gp, x.col(t), u.col(t)) - truth.next(x.col(t), u.col(t));
    sq += e.array().square().matrix();
  }
  return (sq / std::max(steps, 1)).array().sqrt().matrix();
}

Trajectory traj(const Matrix& x, const Matrix& u) {
  Trajectory out;
  out.x = x;
  out.u = u;
  return out;
}

void print_vector(const char* label, const Vector& v) {
  std::printf("%s", label);
  for (int i = 0; i < v.size(); ++i) std::printf(" %.3g", v(i));
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s SYSTEM DATA.csv ROWS MAX_ITERATIONS [TASK_INDEX] [SEED] [MAX_SECONDS]\n", argv[0]);
    return 2;
  }
  const std::string system = argv[1];
  const std::string data_source = argv[2];
  int rows = std::stoi(argv[3]);
  const int max_iterations = std::stoi(argv[4]);
  const int task_index = argc > 5 ? std::stoi(argv[5]) : 0;
  const std::uint64_t seed = argc > 6 ? std::stoull(argv[6]) : 1;

  const RunConfig config = load_run_config(system, std::nullopt);
  const RunTask& task = config.tasks.at(static_cast<std::size_t>(task_index));
  const RunModels models = make_run_models(config);
  const QuadraticCost cost = make_task_cost(config, task);
  const int n = static_cast<int>(task.x0.size()), m = static_cast<int>(config.u_init.size());
  const TaskContext context{config, task, task_index, models, cost, {}, nullptr, 1};
  const Plan reference = plan_with_ddp(context, models.world, DdpVariant::ILQG, Matrix());  // ilqg_real's
  Matrix all;
  if (data_source == "synthetic") {
    // Abundant data where the task goes: ROWS transitions of the real world from states scattered
    // around ilqg_real's plan (positions 0.2 m, velocities 0.3 m/s, angles 0.15 rad, rates 0.5 rad/s)
    // with controls scattered around its controls (0.5 N), measured with the sensors' noise.
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    std::uniform_int_distribution<int> step(0, task.horizon - 1);
    Vector spread(n);
    spread << 0.2, 0.2, 0.2, 0.3, 0.3, 0.3, 0.15, 0.15, 0.15, 0.5, 0.5, 0.5;
    all.resize(rows, 2 * n + m);
    for (int i = 0; i < rows; ++i) {
      const int t = step(rng);
      Vector x = reference.policy.x_bar.col(t), u = reference.policy.u_bar.col(t);
      for (int j = 0; j < n; ++j) x(j) += spread(j) * normal(rng);
      for (int j = 0; j < m; ++j) u(j) += 0.5 * normal(rng);
      Vector x_next = models.world->next(x, u);
      Vector x_measured = x;
      for (int j = 0; j < n; ++j) {
        x_measured(j) += config.observation_std(j) * normal(rng);
        x_next(j) += config.observation_std(j) * normal(rng);
      }
      all.row(i) << x_measured.transpose(), u.transpose(), (x_next - x_measured).transpose();
    }
    std::printf("synthetic data: %d transitions around ilqg_real's plan (its cost on the world %.4g)\n", rows,
                reference.nominal_cost);
  } else {
    all = read_csv(data_source);
  }
  const Matrix data = all.topRows(rows);
  Matrix inputs(rows, n + m);
  inputs << data.leftCols(n), data.middleCols(n, m);
  const Matrix increments = data.rightCols(n);

  const auto backend = gp::make_backend(config.pddp_backend, config.gp.backend_settings);
  gp::FitOptions fit;
  fit.restarts = config.gp.restarts;
  fit.max_evaluations = config.gp.max_evaluations;
  fit.seed = gp_fit_seed(seed, task_index, "pddp", rows);
  if (const char* e = std::getenv("DIAG_MIN_NOISE")) fit.min_noise_std = std::stod(e);  // floor on every sn
  std::vector<gp::FitSummary> summaries;
  const auto dynamics = gp::GpBeliefDynamics::fit(n, m, config.dt, inputs, increments, *backend, fit, &summaries, 1);
  for (const auto& s : summaries) std::printf("fit: %s\n", s.one_line().c_str());


  PddpProblem problem;
  problem.model = &dynamics;
  problem.cost = &cost;
  problem.x0 = task.x0;
  problem.Sigma0 = config.observation_std.array().square().matrix().asDiagonal();
  problem.horizon = task.horizon;
  problem.u_min = config.u_min;
  problem.u_max = config.u_max;
  DdpOptions options = config.solver;
  options.max_iterations = max_iterations;
  if (argc > 7) options.max_seconds = std::stod(argv[7]);
  options.on_iteration = [](const DdpIteration& it) {
    std::printf("  it %2d cost %.6g lambda %.3g step %.3g expected %.3g actual %.3g |g| %.3g failures %d %s\n",
                it.iteration, it.cost, it.lambda, it.step, it.expected_reduction, it.actual_reduction,
                it.gradient_norm, it.backward_failures, it.accepted ? "accepted" : "rejected");
    std::fflush(stdout);
    return true;
  };
  // Variations for experiments (environment): initial control per rotor, limits, regularisation.
  Vector u_init = config.u_init;
  if (const char* e = std::getenv("DIAG_U_INIT")) u_init.setConstant(std::stod(e));
  if (const char* e = std::getenv("DIAG_U_MIN")) problem.u_min = Vector::Constant(m, std::stod(e));
  if (const char* e = std::getenv("DIAG_U_MAX")) problem.u_max = Vector::Constant(m, std::stod(e));
  if (const char* e = std::getenv("DIAG_LAMBDA0")) options.lambda_initial = std::stod(e);
  if (const char* e = std::getenv("DIAG_REG")) options.regularization = *parse_regularization(e);
  // DIAG_START_REFERENCE: start from ilqg_real's controls (the optimum on the true model).
  const Matrix u_start = std::getenv("DIAG_START_REFERENCE") ? reference.policy.u_bar : Matrix(u_init.replicate(1, task.horizon));
  const PddpResult result = solve_pddp(problem, u_start, options);
  std::printf("%s\n", result.belief.summary.report("pddp").c_str());
  const AffinePolicy& policy = result.state_policy;
  const int T = task.horizon;

  print_state_rows("x_bar (PDDP's predicted mean)", policy.x_bar, &policy.u_bar);
  double kmax = 0.0;
  for (const auto& K : policy.K) kmax = std::max(kmax, K.cwiseAbs().maxCoeff());
  std::printf("u_bar min %.3f max %.3f; |K|max %.3g; |K_0|max %.3g\n", policy.u_bar.minCoeff(), policy.u_bar.maxCoeff(),
              kmax, policy.K[0].cwiseAbs().maxCoeff());
  std::printf("belief covariance: sqrt(diag Sigma_t) at t = 0, 10, 20, 30, 40\n");
  for (int t = 0; t <= T; t += 10) print_vector("  ", result.covariance[static_cast<std::size_t>(t)].diagonal().cwiseSqrt());
  std::printf("predicted expected cost %.6g; cost of x_bar, u_bar %.6g\n", result.belief.expected_cost,
              trajectory_cost(cost, traj(policy.x_bar, policy.u_bar)));

  // Open loop u_bar on the GP mean (point beliefs), the simulator and the real world, no noise.
  Matrix x_gp(n, T + 1);
  x_gp.col(0) = task.x0;
  for (int t = 0; t < T; ++t) x_gp.col(t + 1) = gp_mean_step(dynamics, x_gp.col(t), policy.u_bar.col(t));
  print_state_rows("open loop u_bar on the GP mean", x_gp, nullptr);
  const auto sim = rollout(*models.simulator, task.x0, policy.u_bar);
  const auto world = rollout(*models.world, task.x0, policy.u_bar);
  print_state_rows("open loop u_bar on the real world (no noise)", world.trajectory.x, nullptr);
  std::printf("open loop costs: GP mean %.4g, simulator %.4g (%s), world %.4g (%s)\n",
              trajectory_cost(cost, traj(x_gp, policy.u_bar)), trajectory_cost(cost, sim.trajectory),
              sim.finite ? "finite" : "diverged", trajectory_cost(cost, world.trajectory),
              world.finite ? "finite" : "diverged");

  // The policy with its feedback on the world: no noise; observation noise only; all noise.
  const Controller act = [&policy](int t, const VectorCRef& x, VectorRef u) { policy.control(t, x, u); };
  std::mt19937_64 rng(7);
  const auto clean = closed_loop_rollout(*models.world, task.x0, T, act, RolloutNoise::None, Vector(), &rng);
  print_state_rows("closed loop on the real world, no noise", clean.trajectory.x, &clean.trajectory.u);
  std::printf("closed loop, no noise: %s after %d steps, cost %.4g\n", clean.finite ? "finite" : "diverged",
              clean.steps_completed, trajectory_cost(cost, clean.trajectory));
  const auto obs = closed_loop_rollout(*models.world, task.x0, T, act, RolloutNoise::None, config.observation_std, &rng);
  std::printf("closed loop, observation noise only: %s after %d steps, cost %.4g\n", obs.finite ? "finite" : "diverged",
              obs.steps_completed, trajectory_cost(cost, obs.trajectory));
  const auto proc = closed_loop_rollout(*models.world, task.x0, T, act, RolloutNoise::Process, Vector(), &rng);
  std::printf("closed loop, process noise only: %s after %d steps, cost %.4g\n", proc.finite ? "finite" : "diverged",
              proc.steps_completed, trajectory_cost(cost, proc.trajectory));
  for (int e = 0; e < 3; ++e) {
    auto r = make_rng(seed, task_index, RandomStream::Evaluation, {static_cast<std::uint64_t>(e)});
    const auto full = closed_loop_rollout(*models.world, task.x0, T, act, RolloutNoise::Process, config.observation_std, &r);
    std::printf("closed loop, evaluation rollout %d: %s after %d steps, cost %.4g\n", e, full.finite ? "finite" : "diverged",
                full.steps_completed, trajectory_cost(cost, full.trajectory));
  }
  // The closed loop on the GP mean itself (no noise): does the plan fly on its own model?
  Matrix x_cl(n, T + 1), u_cl(m, T);
  x_cl.col(0) = task.x0;
  for (int t = 0; t < T; ++t) {
    Vector u(m);
    policy.control(t, x_cl.col(t), u);
    u_cl.col(t) = u;
    x_cl.col(t + 1) = gp_mean_step(dynamics, x_cl.col(t), u);
  }
  std::printf("closed loop on the GP mean: cost %.4g; |x_cl - x_bar|max %.3g\n",
              trajectory_cost(cost, traj(x_cl, u_cl)), (x_cl - policy.x_bar).cwiseAbs().maxCoeff());

  // GP one-step error (RMS over steps, per state) along: the data, x_bar, the clean closed loop.
  Matrix dx(n, rows), du(m, rows);
  dx = data.leftCols(n).transpose();
  du = data.middleCols(n, m).transpose();
  print_vector("GP one-step RMS error on its data      :", one_step_error(dynamics, *models.world, dx, du, rows));
  print_vector("GP one-step RMS error along x_bar      :", one_step_error(dynamics, *models.world, policy.x_bar, policy.u_bar, T));
  const int done = clean.steps_completed;
  print_vector("GP one-step RMS error along closed loop:",
               one_step_error(dynamics, *models.world, clean.trajectory.x, clean.trajectory.u, std::max(1, std::min(done, T))));
  return 0;
}
