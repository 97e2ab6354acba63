#pragma once
/// The cart-pole swing-up cost the DDP tests share (the reference optima of tests/reference/ilqr_cartpole
/// use it): from rest at theta = 0 to the pole upright, theta = pi, at rest;
/// l = 0.5 (x - goal)' Q (x - goal) + 0.5 u' R u per step, R = 0.1, Qf = diag(100, 100, 1000, 100).

#include <numbers>

#include "gpilqg/core/cost.hpp"

namespace gpilqg::test {

inline QuadraticCost cartpole_swingup_cost(double dt, const Matrix& Q) {
  Vector goal(4);
  goal << 0, 0, std::numbers::pi, 0;
  return QuadraticCost(dt, Q, Matrix::Constant(1, 1, 0.1), Vector(Eigen::Vector4d(100, 100, 1000, 100)).asDiagonal(),
                       goal);
}

}  // namespace gpilqg::test
