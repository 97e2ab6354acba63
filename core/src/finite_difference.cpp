#include "gpilqg/core/finite_difference.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gpilqg {

Matrix central_difference_jacobian(const VectorFunction& g, const Vector& at, int rows, double step) {
  Matrix J(rows, at.size());
  Vector arg = at;
  Vector plus(rows), minus(rows);
  for (Eigen::Index j = 0; j < at.size(); ++j) {
    const double h = step * std::max(1.0, std::abs(at(j)));
    arg(j) = at(j) + h;
    g(arg, plus);
    arg(j) = at(j) - h;
    g(arg, minus);
    arg(j) = at(j);
    // The actual distance between the two points, which differs from 2h by round-off.
    J.col(j) = (plus - minus) / ((at(j) + h) - (at(j) - h));
  }
  return J;
}

namespace {

void check_step(double step) {
  if (!std::isfinite(step) || step <= 0.0)
    throw std::invalid_argument("finite-difference step = " + std::to_string(step) +
                                "; expected a finite value > 0");
}

/// Fills the Jacobians of sim(x, u) with respect to x and u by central differences.
void differentiate(const std::function<void(const Vector&, const Vector&, Vector&)>& sim, const Vector& x,
                   const Vector& u, int n, double step, Matrix& dx, Matrix& du) {
  dx = central_difference_jacobian([&](const Vector& xs, Vector& out) { sim(xs, u, out); }, x, n, step);
  du = central_difference_jacobian([&](const Vector& us, Vector& out) { sim(x, us, out); }, u, n, step);
}

}  // namespace

FiniteDifferenceDynamics::FiniteDifferenceDynamics(std::string name, std::vector<Quantity> states,
                                                   std::vector<Quantity> controls,
                                                   std::vector<Parameter> parameters,
                                                   ContinuousSimulator simulator, double step)
    : name_(std::move(name)),
      states_(std::move(states)),
      controls_(std::move(controls)),
      parameters_(std::move(parameters)),
      simulator_(std::move(simulator)),
      step_(step) {
  if (!simulator_) throw std::invalid_argument("FiniteDifferenceDynamics '" + name_ + "': no simulator");
  if (states_.empty()) throw std::invalid_argument("FiniteDifferenceDynamics '" + name_ + "': no states");
  check_step(step_);
}

void FiniteDifferenceDynamics::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                                        DynamicsJacobians* jacobians) const {
  const int n = state_dim();
  Vector xv = x, uv = u, out(n);
  simulator_(xv, uv, out);
  xdot = out;
  if (jacobians) {
    jacobians->resize(n, control_dim());
    differentiate(simulator_, xv, uv, n, step_, jacobians->fx, jacobians->fu);
  }
}

FiniteDifferenceStepModel::FiniteDifferenceStepModel(int state_dim, int control_dim, double dt,
                                                     DiscreteSimulator simulator, double step)
    : n_(state_dim), m_(control_dim), dt_(dt), simulator_(std::move(simulator)), step_(step) {
  if (!simulator_) throw std::invalid_argument("FiniteDifferenceStepModel: no simulator");
  if (n_ < 1 || m_ < 0)
    throw std::invalid_argument("FiniteDifferenceStepModel: dimensions n = " + std::to_string(n_) +
                                ", m = " + std::to_string(m_) + "; expected n >= 1, m >= 0");
  if (!std::isfinite(dt) || dt <= 0.0)
    throw std::invalid_argument("FiniteDifferenceStepModel: dt = " + std::to_string(dt) +
                                "; expected a finite value > 0");
  check_step(step_);
}

void FiniteDifferenceStepModel::step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next,
                                     StepJacobians* jacobians, StepWorkspace&) const {
  Vector xv = x, uv = u, out(n_);
  simulator_(xv, uv, out);
  x_next = out;
  if (jacobians) {
    jacobians->resize(n_, m_);
    differentiate(simulator_, xv, uv, n_, step_, jacobians->A, jacobians->B);
  }
}

}  // namespace gpilqg
