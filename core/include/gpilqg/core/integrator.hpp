#pragma once
/// @file integrator.hpp
/// Discretisation of a continuous Dynamics into a StepModel with exact Jacobians.
///
/// Explicit Euler (the paper's):  x' = x + dt f(x, u),  A = I + dt f_x,  B = dt f_u.
/// Classical RK4 with zero-order-hold control:
///   k1 = f(x, u), k2 = f(x + dt/2 k1, u), k3 = f(x + dt/2 k2, u), k4 = f(x + dt k3, u)
///   x' = x + dt/6 (k1 + 2 k2 + 2 k3 + k4)
/// with A and B by the chain rule through the four stages, e.g. dk2/dx = f_x(x2) (I + dt/2 dk1/dx),
/// dk2/du = f_x(x2) dt/2 dk1/du + f_u(x2). `substeps` > 1 splits dt into equal sub-steps and chains
/// their Jacobians (A = A_s ... A_1, B accumulated), used for finely integrated "real-world" rollouts.
/// Noise is Euler-Maruyama over the whole step: F is evaluated at (x, u).

#include <memory>
#include <optional>
#include <string_view>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg {

enum class Integrator { Euler, RK4 };

/// "euler" or "rk4"; std::nullopt for anything else.
std::optional<Integrator> parse_integrator(std::string_view name);
std::string_view to_string(Integrator integrator);

class IntegratedStepModel final : public StepModel {
 public:
  /// Throws std::invalid_argument when dt is not positive and finite, substeps < 1, or dynamics is null.
  IntegratedStepModel(DynamicsPtr dynamics, Integrator integrator, double dt, int substeps = 1);

  int state_dim() const override { return dynamics_->state_dim(); }
  int control_dim() const override { return dynamics_->control_dim(); }
  double dt() const override { return dt_; }
  Integrator integrator() const { return integrator_; }
  int substeps() const { return substeps_; }
  const Dynamics& dynamics() const { return *dynamics_; }

  /// Holds the stages of the integrator and the dynamics' workspace.
  std::unique_ptr<StepWorkspace> make_workspace() const override;
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians,
            StepWorkspace& workspace) const override;

  int noise_dim() const override { return dynamics_->noise_dim(); }
  using StepModel::noise;
  void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
             StepWorkspace& workspace) const override;

 private:
  struct Workspace;
  /// One sub-step of length h from x; on return x holds the new state. When jac is not null, the
  /// sub-step's own A and B are written there.
  void substep(Vector& x, const VectorCRef& u, double h, StepJacobians* jac, Workspace& ws) const;

  DynamicsPtr dynamics_;
  Integrator integrator_;
  double dt_;
  int substeps_;
};

/// The discrete-time simulator of `dynamics` at step dt. A system with its own integrator
/// (OwnIntegrator, e.g. a MuJoCo model), bare or decorated by EffectDynamics, gives its own step model
/// and `integrator` and `substeps` are not used; every other system gives
/// IntegratedStepModel(dynamics, integrator, dt, substeps). Throws std::invalid_argument like either.
std::shared_ptr<const StepModel> make_step_model(DynamicsPtr dynamics, Integrator integrator, double dt,
                                                 int substeps = 1);

/// The OwnIntegrator behind `dynamics` (itself or the base an EffectDynamics decorates), or null.
const OwnIntegrator* own_integrator(const Dynamics& dynamics);

}  // namespace gpilqg
