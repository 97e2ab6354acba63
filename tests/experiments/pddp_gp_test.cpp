// PDDP end to end on a known system: GPs fitted by maximum likelihood to abundant transitions of a
// damped pendulum (a black box), exact moment matching, DDP over the belief. Its solution approaches
// iLQR's on the true system: the same controls to a few percent, and nearly the same true cost.

#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "gpilqg/control/belief_space.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/gp_belief_dynamics.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

constexpr double kPendulumDt = 0.05;
constexpr int kT = 40;

std::shared_ptr<const Dynamics> pendulum_dynamics() {
  return std::make_shared<FiniteDifferenceDynamics>(
      "pendulum", std::vector<Quantity>{{"theta", "rad"}, {"omega", "rad/s"}}, std::vector<Quantity>{{"torque", "N m"}},
      std::vector<Parameter>{}, [](const Vector& x, const Vector& u, Vector& xdot) {
        xdot(0) = x(1);
        xdot(1) = -9.81 * std::sin(x(0)) - 0.5 * x(1) + u(0);
      });
}

double true_cost(const StepModel& model, const Cost& cost, const Matrix& u) {
  const auto r = rollout(model, Vector::Zero(2), u);
  double J = cost.terminal(r.trajectory.x.col(kT));
  for (int t = 0; t < kT; ++t) J += cost.stage(t, r.trajectory.x.col(t), u.col(t));
  return J;
}

TEST(PddpWithGp, WithAbundantDataItApproachesIlqrOnTheTrueSystem) {
  IntegratedStepModel truth(pendulum_dynamics(), Integrator::RK4, kPendulumDt);
  Vector goal(2);
  goal << 1.0, 0.0;
  const QuadraticCost cost(kPendulumDt, Vector(Eigen::Vector2d(1.0, 0.1)).asDiagonal(), Matrix::Constant(1, 1, 0.1),
                           Vector(Eigen::Vector2d(100.0, 10.0)).asDiagonal(), goal);

  // 300 measured transitions spread over the region the task visits, with measurement noise 1e-3
  // (noise-free targets would pin the GP noise at its floor and make K^-1 needlessly ill-conditioned).
  const int N = 300;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> theta(-0.5, 1.5), omega(-3.0, 3.0), torque(-2.0, 14.0);
  std::normal_distribution<double> noise(0.0, 1e-3);
  Matrix inputs(N, 3), increments(N, 2);
  for (int i = 0; i < N; ++i) {
    const Vector x(Eigen::Vector2d(theta(rng), omega(rng)));
    const Vector u = Vector::Constant(1, torque(rng));
    inputs.row(i) << x(0), x(1), u(0);
    increments.row(i) = (truth.next(x, u) - x).transpose();
    increments(i, 0) += noise(rng);
    increments(i, 1) += noise(rng);
  }
  gp::FitOptions fit;
  fit.restarts = 1;
  const gp::ExactGpBackend backend;
  std::vector<gp::FitSummary> summaries;
  const auto dynamics = gp::GpBeliefDynamics::fit(2, 1, kPendulumDt, inputs, increments, backend, fit, &summaries);
  for (const auto& s : summaries) std::printf("%s\n", s.one_line().c_str());

  PddpProblem pddp{&dynamics, &cost, Vector::Zero(2), Matrix::Zero(2, 2), kT, {}, {}};
  // A learned model's derivatives carry the GP's numerical noise (~1e-6 here), so stationarity is asked
  // to 1e-4 in dJ/du, far below what moves the controls; the reference is solved tightly.
  DdpOptions options;
  options.cost_tolerance = 1e-8;
  options.gradient_tolerance = 1e-4;
  // No wall-time cap: under the sanitizers on a busy 2-core machine the solve takes over 60 s, and the
  // result must not depend on the machine's load.
  options.max_seconds = 1e9;
  const PddpResult learned = solve_pddp(pddp, Matrix::Zero(1, kT), options);
  DdpOptions tight;
  tight.cost_tolerance = 1e-12;
  DdpSolver solver(tight);
  const DdpResult reference = solver.solve(DdpProblem{&truth, &cost, Vector::Zero(2), kT, {}, {}}, Matrix::Zero(1, kT));

  // Converged, or stopped where the learned model's derivative noise stops progress: with the GP
  // fitted by this machine's BLAS the regularisation limit was reached at |g| = 1.3e-4, the controls
  // within 0.03 of iLQR's and the true cost within 0.03% (checked below either way).
  const auto& summary = learned.belief.summary;
  EXPECT_TRUE(converged(summary.termination) ||
              (summary.termination == DdpTermination::RegularizationLimit && summary.final_gradient_norm < 1e-3))
      << summary.report("pddp");
  Eigen::SelfAdjointEigenSolver<Matrix> final_covariance(learned.covariance.back());
  EXPECT_GE(final_covariance.eigenvalues().minCoeff(), -1e-12);  // the belief stays a belief
  const double u_scale = reference.trajectory.u.cwiseAbs().maxCoeff();
  const double u_error = (learned.belief.trajectory.u - reference.trajectory.u).cwiseAbs().maxCoeff();
  const double pddp_true_cost = true_cost(truth, cost, learned.belief.trajectory.u);
  std::printf("%s\nmax |u_pddp - u_ilqr| = %.4f (max |u| %.3f); true cost: pddp %.6f, ilqr %.6f; final Sigma trace %.2e\n",
              learned.belief.summary.report("pddp").c_str(), u_error, u_scale, pddp_true_cost, reference.nominal_cost,
              learned.covariance.back().trace());
  EXPECT_LT(u_error, 0.05 * u_scale);
  EXPECT_LT(pddp_true_cost, 1.02 * reference.nominal_cost);
  EXPECT_LT(learned.covariance.back().trace(), 1e-3);  // abundant data: little uncertainty left
}

}  // namespace
}  // namespace gpilqg
