#pragma once
/// @file step_model.hpp
/// Discrete-time models, the interface every controller works against (docs/architecture.md#layers).
///
/// The paper's discrete stochastic step (its eq. for x' in the Robust-ILQG section):
///
///   x' = x + (f_sim + eps_hat) dt + F xi sqrt(dt) + G xi_G sqrt(dt),   xi ~ N(0, I_p), xi_G ~ N(0, I_q)
///
/// A StepModel returns the mean step x' = phi(x, u) with A = dphi/dx and B = dphi/du, the noise columns
/// F (n x p) and the model-uncertainty columns G (n x q), each with the derivatives of every column.
/// F and G are the continuous-time amplifications; the caller multiplies by sqrt(dt) (paper, appendix).
/// iLQR uses the mean only, iLQG adds F, Robust-iLQG adds F and G.

#include <memory>
#include <string>
#include <optional>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/noise.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// A = d x' / d x (n x n), B = d x' / d u (n x m).
struct StepJacobians {
  Matrix A;
  Matrix B;
  void resize(int n, int m);
};

/// The scratch space of one caller of a StepModel (Crocoddyl's model/data split): made by the model's
/// make_workspace(), owned by the caller, used by one thread at a time and reused from call to call,
/// so that a solver's passes do not allocate. The step, noise and uncertainty at the same (x, u) may
/// share work through it (the GP residual model's predictions). Models with scratch derive from it.
struct StepWorkspace {
  virtual ~StepWorkspace() = default;
};

/// A discrete-time model. Immutable once built and shareable between threads; all scratch space
/// belongs to the caller. Each call (step, noise, uncertainty) is one virtual function that takes the
/// caller's workspace (from make_workspace(); what hot loops hold from call to call) and that
/// implementations override; a model without scratch ignores the workspace. The form without a
/// workspace is a non-virtual convenience of this class that makes a temporary one. An implementation
/// brings those forms into its own scope with `using StepModel::step;` (and noise, uncertainty).
class StepModel {
 public:
  virtual ~StepModel() = default;

  /// A workspace for this model's calls (the default is empty).
  virtual std::unique_ptr<StepWorkspace> make_workspace() const { return std::make_unique<StepWorkspace>(); }

  virtual int state_dim() const = 0;
  virtual int control_dim() const = 0;
  /// The step length dt [s].
  virtual double dt() const = 0;

  /// Mean step x' = phi(x, u) in the caller's workspace; fills A and B when `jacobians` is not null.
  virtual void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians,
                    StepWorkspace& workspace) const = 0;
  /// The same with a temporary workspace.
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians = nullptr) const;
  /// True when step() with Jacobians costs little more than without, because the work both share
  /// dominates (a belief step by moment matching: the N x N kernel expectations). DDP then asks for
  /// the Jacobians during its line search and its derivative pass reuses those of the accepted
  /// candidate instead of stepping the whole trajectory again (ddp_solver.cpp).
  virtual bool jacobians_nearly_free() const { return false; }

  /// Number of process-noise columns p (0: deterministic).
  virtual int noise_dim() const { return 0; }
  /// F(x, u) with the derivatives of its columns when `derivatives` is true, in the caller's
  /// workspace. The default has no columns (p = 0).
  virtual void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
                     StepWorkspace& workspace) const;
  /// The same with a temporary workspace.
  void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives) const;

  /// Number of model-uncertainty columns q (0 for a model without learned uncertainty).
  virtual int uncertainty_dim() const { return 0; }
  /// G(x, u) with the derivatives of its columns (a GP residual model: G = diag(sigma_i(z))), in the
  /// caller's workspace. The default has no columns (q = 0).
  virtual void uncertainty(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
                           StepWorkspace& workspace) const;
  /// The same with a temporary workspace.
  void uncertainty(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives) const;

  /// Convenience: returns phi(x, u).
  Vector next(const VectorCRef& x, const VectorCRef& u) const;
};

/// A system whose simulator is its own discrete-time integrator rather than one of integrator.hpp's:
/// a MuJoCo model steps with its own integrator and timestep (docs/own-system.md#5-how-it-works).
/// make_step_model (integrator.hpp) asks for it.
class OwnIntegrator {
 public:
  virtual ~OwnIntegrator() = default;
  /// The step model of `decorated` at step dt: `decorated` is this system, or a Dynamics decorating
  /// it (EffectDynamics) whose gain and forces the step must include. Throws std::invalid_argument
  /// when dt does not suit the system (for MuJoCo: not a whole multiple of the timestep).
  virtual std::shared_ptr<const StepModel> own_step_model(std::shared_ptr<const Dynamics> decorated,
                                                          double dt) const = 0;
  /// Why a step of dt does not suit the system (own_step_model's refusal, e.g. "dt = 0.015 s is not a
  /// whole multiple of the MuJoCo model's timestep 0.01 s ..."), or nothing when it does: callers that
  /// take dt from measurements name the data as the cause.
  virtual std::optional<std::string> step_problem(double dt) const = 0;
};

}  // namespace gpilqg
