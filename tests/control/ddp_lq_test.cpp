// The engine against closed-form answers on linear models: the discrete Riccati solution (iLQR in one
// iteration), the trace terms of iLQG with additive noise (and a Monte Carlo estimate), the shrinking
// controls under control-dependent noise, and Robust-iLQG's reductions and Monte Carlo agreement.

#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include <gtest/gtest.h>

#include "gpilqg/control/ddp_solver.hpp"
#include "linear_models.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

constexpr int kN = 4, kM = 2, kT = 30;
constexpr double kLqDt = 0.1;

struct LqSetup {
  test::LinearStepModel model;
  QuadraticCost cost;
  Vector x0;
  Matrix Q, R, Qf;  // continuous weights as given to the cost
};

LqSetup random_lq(unsigned seed) {
  const Matrix F = test::random_vector(kN * kN, -0.5, 0.5, seed).reshaped(kN, kN);
  const Matrix A = Matrix::Identity(kN, kN) + kLqDt * F;
  const Matrix B = kLqDt * test::random_vector(kN * kM, -1.0, 1.0, seed + 1).reshaped(kN, kM);
  const Matrix L = test::random_vector(kN * kN, -1.0, 1.0, seed + 2).reshaped(kN, kN);
  const Matrix Q = L * L.transpose() + 0.1 * Matrix::Identity(kN, kN);
  const Matrix R = Matrix::Identity(kM, kM) * 0.5;
  const Matrix Qf = 10.0 * Matrix::Identity(kN, kN);
  return {test::LinearStepModel(A, B, kLqDt), QuadraticCost(kLqDt, Q, R, Qf, Vector::Zero(kN)),
          test::random_vector(kN, -2.0, 2.0, seed + 3), Q, R, Qf};
}

DdpProblem problem_of(const LqSetup& s) {
  DdpProblem p;
  p.model = &s.model;
  p.cost = &s.cost;
  p.x0 = s.x0;
  p.horizon = kT;
  return p;
}

DdpOptions exact_newton(DdpVariant variant) {
  DdpOptions o;
  o.variant = variant;
  o.lambda_initial = 0.0;  // a pure Newton step: the LQ solution in one iteration
  o.cost_tolerance = 1e-14;
  o.gradient_tolerance = 1e-10;
  return o;
}

/// The discrete Riccati recursion for l_t = dt (0.5 x'Qx + 0.5 u'Ru), l_T = 0.5 x'Qf x:
/// P_T = Qf,  K_t = -(dt R + B'P B)^-1 B'P A,  P_t = dt Q + A'P A + A'P B K_t.
struct Riccati {
  std::vector<Matrix> P, K;
};
Riccati riccati(const LqSetup& s, const Matrix& A, const Matrix& B) {
  Riccati r;
  r.P.assign(kT + 1, Matrix());
  r.K.assign(kT, Matrix());
  r.P[kT] = s.Qf;
  for (int t = kT - 1; t >= 0; --t) {
    const Matrix& P = r.P[static_cast<std::size_t>(t + 1)];
    const Matrix H = kLqDt * s.R + B.transpose() * P * B;
    r.K[static_cast<std::size_t>(t)] = -H.ldlt().solve(B.transpose() * P * A);
    r.P[static_cast<std::size_t>(t)] = kLqDt * s.Q + A.transpose() * P * A + A.transpose() * P * B * r.K[static_cast<std::size_t>(t)];
  }
  return r;
}

Matrix system_A(const LqSetup& s) { StepJacobians j; Vector x(kN); s.model.step(s.x0, Vector::Zero(kM), x, &j); return j.A; }
Matrix system_B(const LqSetup& s) { StepJacobians j; Vector x(kN); s.model.step(s.x0, Vector::Zero(kM), x, &j); return j.B; }

/// Monte Carlo estimate of the closed-loop cost: mean and standard error over `samples` rollouts.
std::pair<double, double> monte_carlo_cost(const StepModel& model, const Cost& cost, const AffinePolicy& policy,
                                           const Vector& x0, bool uncertainty, int samples, unsigned seed) {
  std::mt19937_64 rng(seed);
  PolicyRolloutSettings settings;
  settings.uncertainty = uncertainty;
  double sum = 0.0, sum2 = 0.0;
  for (int k = 0; k < samples; ++k) {
    const auto r = rollout_policy(model, policy, x0, settings, rng);
    double J = cost.terminal(r.trajectory.x.col(policy.horizon()));
    for (int t = 0; t < policy.horizon(); ++t) J += cost.stage(t, r.trajectory.x.col(t), r.trajectory.u.col(t));
    sum += J;
    sum2 += J * J;
  }
  const double mean = sum / samples;
  const double var = (sum2 / samples - mean * mean) * samples / (samples - 1.0);
  return {mean, std::sqrt(var / samples)};
}

TEST(DdpLinearQuadratic, IlqrConvergesInOneIterationToTheRiccatiSolution) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const LqSetup s = random_lq(seed * 10);
    DdpSolver solver(exact_newton(DdpVariant::ILQR));
    const DdpResult result = solver.solve(problem_of(s), Matrix::Zero(kM, kT));
    const Riccati r = riccati(s, system_A(s), system_B(s));
    const double riccati_cost = 0.5 * s.x0.dot(r.P[0] * s.x0);

    ASSERT_GE(result.summary.trace.size(), 1u);
    const DdpIteration& first = result.summary.trace[0];
    EXPECT_TRUE(first.accepted);
    EXPECT_EQ(first.step, 1.0);
    EXPECT_NEAR(first.cost, riccati_cost, 1e-10 * riccati_cost) << "cost after the first iteration";
    EXPECT_LE(result.summary.iterations, 2) << result.summary.report("ilqr");
    EXPECT_TRUE(converged(result.summary.termination));
    EXPECT_NEAR(result.nominal_cost, riccati_cost, 1e-10 * riccati_cost);
    for (int t = 0; t < kT; ++t) {
      EXPECT_TRUE(test::matrices_near(result.policy.K[static_cast<std::size_t>(t)], r.K[static_cast<std::size_t>(t)], 1e-10, 1e-10)) << "t = " << t;
      EXPECT_TRUE(test::matrices_near(result.value_hessians[static_cast<std::size_t>(t)], r.P[static_cast<std::size_t>(t)], 1e-10, 1e-10)) << "t = " << t;
    }
  }
}

TEST(DdpLinearQuadratic, IlqgWithAdditiveNoiseKeepsTheGainsAndAddsTheTraceTerms) {
  LqSetup s = random_lq(7);
  s.model.additive_std = 0.4;
  DdpSolver ilqr(exact_newton(DdpVariant::ILQR)), ilqg(exact_newton(DdpVariant::ILQG));
  const DdpResult det = ilqr.solve(problem_of(s), Matrix::Zero(kM, kT));
  const DdpResult sto = ilqg.solve(problem_of(s), Matrix::Zero(kM, kT));
  for (int t = 0; t < kT; ++t)
    EXPECT_TRUE(test::matrices_near(sto.policy.K[static_cast<std::size_t>(t)], det.policy.K[static_cast<std::size_t>(t)], 1e-12, 1e-12));
  EXPECT_TRUE(test::matrices_near(sto.trajectory.u, det.trajectory.u, 1e-12, 1e-12));

  // The trace terms in closed form: sum_t 0.5 dt sigma^2 tr(P_{t+1}) with the Riccati P.
  const Riccati r = riccati(s, system_A(s), system_B(s));
  double trace_terms = 0.0;
  for (int t = 0; t < kT; ++t) trace_terms += 0.5 * kLqDt * 0.4 * 0.4 * r.P[static_cast<std::size_t>(t + 1)].trace();
  EXPECT_NEAR(sto.nominal_cost, det.nominal_cost, 1e-12 * det.nominal_cost);
  EXPECT_NEAR(sto.expected_cost - sto.nominal_cost, trace_terms, 1e-10 * trace_terms);
  EXPECT_GT(trace_terms, 0.01 * sto.nominal_cost);  // the noise matters in this test

  const auto [mean, se] = monte_carlo_cost(s.model, s.cost, sto.policy, s.x0, false, 4000, 11);
  EXPECT_NEAR(mean, sto.expected_cost, 3.0 * se) << "Monte Carlo " << mean << " +- " << se;
}

TEST(DdpLinearQuadratic, ControlMagnitudeShrinksAsControlDependentNoiseGrows) {
  double previous = std::numeric_limits<double>::infinity();
  Matrix deterministic_u;
  for (double sigma : {0.0, 0.5, 1.0, 2.0}) {
    LqSetup s = random_lq(21);
    s.model.multiplicative_std = sigma;
    DdpSolver ilqg(exact_newton(DdpVariant::ILQG));
    const DdpResult result = ilqg.solve(problem_of(s), Matrix::Zero(kM, kT));
    EXPECT_TRUE(converged(result.summary.termination)) << result.summary.report("ilqg");
    const double magnitude = result.trajectory.u.norm();
    EXPECT_LT(magnitude, previous) << "sigma = " << sigma;
    previous = magnitude;
    // iLQR ignores the noise altogether.
    DdpSolver ilqr(exact_newton(DdpVariant::ILQR));
    const Matrix u_ilqr = ilqr.solve(problem_of(s), Matrix::Zero(kM, kT)).trajectory.u;
    if (deterministic_u.size() == 0) deterministic_u = u_ilqr;
    EXPECT_TRUE(test::matrices_near(u_ilqr, deterministic_u, 1e-12, 1e-12));
  }
}

TEST(DdpLinearQuadratic, IlqgPredictedCostMatchesMonteCarloUnderControlDependentNoise) {
  LqSetup s = random_lq(33);
  s.model.multiplicative_std = 1.0;
  s.model.additive_std = 0.2;
  DdpSolver ilqg(exact_newton(DdpVariant::ILQG));
  const DdpResult result = ilqg.solve(problem_of(s), Matrix::Zero(kM, kT));
  const auto [mean, se] = monte_carlo_cost(s.model, s.cost, result.policy, s.x0, false, 4000, 5);
  EXPECT_NEAR(mean, result.expected_cost, 3.0 * se) << "Monte Carlo " << mean << " +- " << se;
}

TEST(DdpRobust, WithZeroUncertaintyColumnsItEqualsIlqgExactly) {
  LqSetup s = random_lq(41);
  s.model.multiplicative_std = 0.7;
  s.model.additive_std = 0.1;
  s.model.zero_uncertainty_columns = true;
  ASSERT_EQ(s.model.uncertainty_dim(), kM);
  DdpOptions o;  // default options: regularisation schedule and line search in play
  o.variant = DdpVariant::ILQG;
  DdpSolver ilqg(o);
  o.variant = DdpVariant::RobustILQG;
  DdpSolver robust(o);
  const DdpResult a = ilqg.solve(problem_of(s), Matrix::Zero(kM, kT));
  const DdpResult b = robust.solve(problem_of(s), Matrix::Zero(kM, kT));
  EXPECT_EQ(a.summary.iterations, b.summary.iterations);
  EXPECT_EQ(a.expected_cost, b.expected_cost);
  EXPECT_TRUE(a.trajectory.u == b.trajectory.u);
  EXPECT_TRUE(a.trajectory.x == b.trajectory.x);
  for (int t = 0; t < kT; ++t) EXPECT_TRUE(a.policy.K[static_cast<std::size_t>(t)] == b.policy.K[static_cast<std::size_t>(t)]);
}

TEST(DdpRobust, UncertaintyGrowingWithControlsMakesItUseSmallerControlsAndItsCostMatchesMonteCarlo) {
  LqSetup s = random_lq(51);
  s.model.multiplicative_std = 0.2;
  s.model.uncertainty_std = 1.5;
  DdpSolver ilqg(exact_newton(DdpVariant::ILQG)), robust(exact_newton(DdpVariant::RobustILQG));
  const DdpResult plain = ilqg.solve(problem_of(s), Matrix::Zero(kM, kT));
  const DdpResult careful = robust.solve(problem_of(s), Matrix::Zero(kM, kT));
  EXPECT_LT(careful.trajectory.u.norm(), 0.95 * plain.trajectory.u.norm());
  // On the model with sampled uncertainty, the robust policy's predicted expected cost is right...
  const auto [mean, se] = monte_carlo_cost(s.model, s.cost, careful.policy, s.x0, true, 4000, 3);
  EXPECT_NEAR(mean, careful.expected_cost, 3.0 * se) << "Monte Carlo " << mean << " +- " << se;
  // ... and it does better there than the policy that ignored the uncertainty.
  const auto [plain_mean, plain_se] = monte_carlo_cost(s.model, s.cost, plain.policy, s.x0, true, 4000, 3);
  EXPECT_LT(mean, plain_mean);
}

}  // namespace
}  // namespace gpilqg
