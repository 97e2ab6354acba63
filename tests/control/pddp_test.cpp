// PDDP's belief layer on the shared engine, against closed forms: on linear-Gaussian belief dynamics
// (mu' = A mu + B u, Sigma' = A Sigma A' + W) PDDP's controls and mean-feedback gains equal iLQR's on the
// mean model, and its cost is iLQR's plus sum_t 0.5 tr(l_xx Sigma_t). Derivatives of the belief cost and
// of the packed belief dynamics against central differences.

#include <gtest/gtest.h>

#include "gpilqg/control/belief_space.hpp"
#include "linear_models.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

/// x' = A x + B u + w, w ~ N(0, W): exact Gaussian belief propagation with exact Jacobians.
class LinearGaussianBelief final : public BeliefStepModel {
 public:
  LinearGaussianBelief(Matrix A, Matrix B, Matrix W, double dt) : A_(std::move(A)), B_(std::move(B)), W_(std::move(W)), dt_(dt) {}
  int state_dim() const override { return static_cast<int>(A_.rows()); }
  int control_dim() const override { return static_cast<int>(B_.cols()); }
  double dt() const override { return dt_; }
  void propagate(const VectorCRef& v, const VectorCRef& u, VectorRef v_next, BeliefJacobians* jac) const override {
    const int n = state_dim(), nb = belief_dim(n);
    Vector mu;
    Matrix Sigma;
    unpack_belief(v, n, mu, Sigma);
    pack_belief(A_ * mu + B_ * u, A_ * Sigma * A_.transpose() + W_, v_next);
    if (!jac) return;
    jac->dv = Matrix::Zero(nb, nb);
    jac->du = Matrix::Zero(nb, control_dim());
    jac->dv.topLeftCorner(n, n) = A_;
    jac->du.topRows(n) = B_;
    for (int j = 0; j < n; ++j)
      for (int i = j; i < n; ++i) {
        Matrix E = Matrix::Zero(n, n);  // moving packed entry (i, j) moves Sigma_ij and Sigma_ji
        E(i, j) = 1.0;
        E(j, i) = 1.0;
        Vector column(nb);
        pack_belief(Vector::Zero(n), A_ * E * A_.transpose(), column);
        jac->dv.col(n + vech_index(n, i, j)) = column;
      }
  }

 private:
  Matrix A_, B_, W_;
  double dt_;
};

struct LinearGaussianSetup {
  Matrix A, B, W, Q, R, Qf;
  Vector x0;
};

LinearGaussianSetup make_setup() {
  LinearGaussianSetup s;
  const double dt = 0.1;
  s.A = Matrix::Identity(3, 3) + dt * test::random_vector(9, -0.5, 0.5, 1).reshaped(3, 3);
  s.B = dt * test::random_vector(6, -1, 1, 2).reshaped(3, 2);
  const Matrix C = test::random_vector(9, -0.3, 0.3, 3).reshaped(3, 3);
  s.W = dt * C * C.transpose();
  const Matrix L = test::random_vector(9, -1, 1, 4).reshaped(3, 3);
  s.Q = L * L.transpose() + 0.1 * Matrix::Identity(3, 3);
  s.R = 0.3 * Matrix::Identity(2, 2);
  s.Qf = 5.0 * Matrix::Identity(3, 3);
  s.x0 = test::random_vector(3, -1, 1, 5);
  return s;
}

TEST(Belief, PackingRoundTripsAndIndexesTheLowerTriangle) {
  EXPECT_EQ(belief_dim(4), 14);   // cart-pole
  EXPECT_EQ(belief_dim(12), 90);  // quadrotor
  EXPECT_EQ(vech_index(3, 0, 0), 0);
  EXPECT_EQ(vech_index(3, 2, 0), 2);
  EXPECT_EQ(vech_index(3, 1, 1), 3);
  EXPECT_EQ(vech_index(3, 1, 2), 4);
  EXPECT_EQ(vech_index(3, 2, 2), 5);
  const Matrix L = test::random_vector(9, -1, 1, 6).reshaped(3, 3);
  const Matrix Sigma = L * L.transpose();
  const Vector mu = test::random_vector(3, -1, 1, 7);
  Vector v(9), mu2;
  Matrix Sigma2;
  pack_belief(mu, Sigma, v);
  unpack_belief(v, 3, mu2, Sigma2);
  EXPECT_MATRIX_NEAR(mu2, mu, 0.0);
  EXPECT_MATRIX_NEAR(Sigma2, Sigma, 1e-15);
  EXPECT_THROW(unpack_belief(Vector::Zero(8), 3, mu2, Sigma2), std::invalid_argument);
}

TEST(Belief, SpaceModelJacobiansMatchCentralDifferences) {
  const LinearGaussianSetup s = make_setup();
  LinearGaussianBelief belief(s.A, s.B, s.W, 0.1);
  BeliefSpaceModel model(belief);
  Vector v(9);
  pack_belief(s.x0, s.W, v);
  const Vector u = test::random_vector(2, -1, 1, 8);
  Vector next(9);
  StepJacobians jac;
  model.step(v, u, next, &jac);
  EXPECT_TRUE(test::matrices_near(jac.A, test::numeric_jacobian([&](const Vector& vs) { return model.next(vs, u); }, v, 1e-6), 1e-8));
  EXPECT_TRUE(test::matrices_near(jac.B, test::numeric_jacobian([&](const Vector& us) { return model.next(v, us); }, u, 1e-6), 1e-8));
}

TEST(Belief, CostIsTheExpectationOfTheQuadraticCostAndItsDerivativesMatch) {
  const LinearGaussianSetup s = make_setup();
  const Vector goal = test::random_vector(3, -1, 1, 9);
  const QuadraticCost cost(0.1, s.Q, s.R, s.Qf, goal);
  const BeliefCost belief_cost(cost);
  const Matrix L = test::random_vector(9, -0.5, 0.5, 10).reshaped(3, 3);
  const Matrix Sigma = L * L.transpose();
  Vector v(9);
  pack_belief(s.x0, Sigma, v);
  const Vector u = test::random_vector(2, -1, 1, 11);
  // E[0.5 dt (x-g)'Q(x-g)] = 0.5 dt ((mu-g)'Q(mu-g) + tr(Q Sigma)).
  EXPECT_NEAR(belief_cost.stage(0, v, u), cost.stage(0, s.x0, u) + 0.5 * 0.1 * (s.Q * Sigma).trace(), 1e-12);
  EXPECT_NEAR(belief_cost.terminal(v), cost.terminal(s.x0) + 0.5 * (s.Qf * Sigma).trace(), 1e-12);
  CostDerivatives d;
  belief_cost.stage(0, v, u, &d);
  auto value = [&](const Vector& vs) { return Vector::Constant(1, belief_cost.stage(0, vs, u)); };
  auto gradient = [&](const Vector& vs) { CostDerivatives g; belief_cost.stage(0, vs, u, &g); return g.lx; };
  EXPECT_TRUE(test::matrices_near(Matrix(d.lx.transpose()), test::numeric_jacobian(value, v, 1e-6), 1e-8));
  EXPECT_TRUE(test::matrices_near(d.lxx, test::numeric_jacobian(gradient, v, 1e-6), 1e-8));
}

TEST(Pddp, OnLinearGaussianBeliefsItIsIlqrOnTheMeanPlusTheCovarianceCost) {
  const LinearGaussianSetup s = make_setup();
  const int T = 25;
  const QuadraticCost cost(0.1, s.Q, s.R, s.Qf, Vector::Zero(3));
  LinearGaussianBelief belief(s.A, s.B, s.W, 0.1);
  DdpOptions options;
  options.lambda_initial = 0.0;
  options.cost_tolerance = 1e-14;
  options.gradient_tolerance = 1e-10;

  PddpProblem pddp{&belief, &cost, s.x0, 0.01 * Matrix::Identity(3, 3), T, {}, {}};
  const PddpResult r = solve_pddp(pddp, Matrix::Zero(2, T), options);

  test::LinearStepModel mean_model(s.A, s.B, 0.1);
  DdpProblem plain{&mean_model, &cost, s.x0, T, {}, {}};
  DdpSolver solver(options);
  const DdpResult ilqr = solver.solve(plain, Matrix::Zero(2, T));

  EXPECT_TRUE(test::matrices_near(r.belief.trajectory.u, ilqr.trajectory.u, 1e-9, 1e-9));
  EXPECT_TRUE(test::matrices_near(r.mean, ilqr.trajectory.x, 1e-9, 1e-9));
  for (int t = 0; t < T; ++t)
    EXPECT_TRUE(test::matrices_near(r.state_policy.K[static_cast<std::size_t>(t)], ilqr.policy.K[static_cast<std::size_t>(t)], 1e-8, 1e-8));
  double covariance_cost = 0.5 * (s.Qf * r.covariance[T]).trace();
  Matrix Sigma = 0.01 * Matrix::Identity(3, 3);
  for (int t = 0; t < T; ++t) {
    EXPECT_TRUE(test::matrices_near(r.covariance[static_cast<std::size_t>(t)], Sigma, 1e-12));
    covariance_cost += 0.5 * 0.1 * (s.Q * Sigma).trace();
    Sigma = s.A * Sigma * s.A.transpose() + s.W;
  }
  EXPECT_NEAR(r.belief.nominal_cost, ilqr.nominal_cost + covariance_cost, 1e-9 * r.belief.nominal_cost);
}

}  // namespace
}  // namespace gpilqg
