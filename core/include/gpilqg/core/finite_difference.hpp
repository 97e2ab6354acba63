#pragma once
/// @file finite_difference.hpp
/// Central differences, and wrappers that give a black-box simulator the Jacobians the solvers need.
///
/// The central difference (g(x + h e_j) - g(x - h e_j)) / (2 h) has truncation error O(h^2 g''') and
/// round-off error O(eps |g| / h); h_j = step * max(1, |x_j|) with step = cbrt(eps) ~ 6e-6 balances the
/// two, giving about 1e-10 relative accuracy for smooth g.

#include <functional>
#include <string>
#include <vector>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg {

/// The default relative step, cbrt(machine epsilon).
inline constexpr double kCentralDifferenceStep = 6.0554544523933395e-06;

/// A vector function g: R^k -> R^r, written into its second argument (already sized r).
using VectorFunction = std::function<void(const Vector& argument, Vector& value)>;

/// The r x k Jacobian of g at `at` by central differences with h_j = step * max(1, |at_j|).
Matrix central_difference_jacobian(const VectorFunction& g, const Vector& at, int rows,
                                   double step = kCentralDifferenceStep);

/// A continuous-time black box: writes f(x, u) into xdot (already sized n).
using ContinuousSimulator = std::function<void(const Vector& x, const Vector& u, Vector& xdot)>;
/// A discrete-time black box: writes the next state into x_next (already sized n).
using DiscreteSimulator = std::function<void(const Vector& x, const Vector& u, Vector& x_next)>;

/// Dynamics whose f comes from a black box and whose Jacobians are central differences.
/// Use it to plug a simulator without derivatives into every solver of the project.
class FiniteDifferenceDynamics final : public Dynamics {
 public:
  FiniteDifferenceDynamics(std::string name, std::vector<Quantity> states,
                           std::vector<Quantity> controls, std::vector<Parameter> parameters,
                           ContinuousSimulator simulator, double step = kCentralDifferenceStep);

  const std::string& name() const override { return name_; }
  const std::vector<Quantity>& states() const override { return states_; }
  const std::vector<Quantity>& controls() const override { return controls_; }
  std::vector<Parameter> parameters() const override { return parameters_; }

  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                DynamicsJacobians* jacobians = nullptr) const override;

 private:
  std::string name_;
  std::vector<Quantity> states_;
  std::vector<Quantity> controls_;
  std::vector<Parameter> parameters_;
  ContinuousSimulator simulator_;
  double step_;
};

/// A deterministic discrete-time black box as a StepModel, with A and B by central differences.
class FiniteDifferenceStepModel final : public StepModel {
 public:
  FiniteDifferenceStepModel(int state_dim, int control_dim, double dt, DiscreteSimulator simulator,
                            double step = kCentralDifferenceStep);

  int state_dim() const override { return n_; }
  int control_dim() const override { return m_; }
  double dt() const override { return dt_; }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians,
            StepWorkspace& workspace) const override;

 private:
  int n_;
  int m_;
  double dt_;
  DiscreteSimulator simulator_;
  double step_;
};

}  // namespace gpilqg
