#pragma once
/// @file dynamics.hpp
/// Continuous-time controlled dynamics xdot = f(x, u) with Jacobians, named quantities and the noise
/// amplification F(x, u) of the paper's stochastic model (eq. 1: dx = f(x, u) dt + F(x, u) dw).

#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/noise.hpp"
#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"
#include "gpilqg/core/workspace.hpp"

namespace gpilqg {

/// Jacobians of f at (x, u): fx = df/dx (n x n), fu = df/du (n x m).
struct DynamicsJacobians {
  Matrix fx;
  Matrix fu;
  void resize(int n, int m);
};

/// The input matrix b(x, u) = df/du (n x m) and its derivatives, the ingredients of actuator noise.
struct InputMatrix {
  Matrix b;                  ///< n x m
  std::vector<Matrix> d_dx;  ///< m entries, each n x n: d b_j / d x (b_j = column j)
  std::vector<Matrix> d_du;  ///< m entries, each n x m: d b_j / d u (zero for control-affine f)
  void resize(int n, int m);
};

/// The scratch space of one caller of a Dynamics (Crocoddyl's model/data split): made by the system's
/// make_workspace(), owned by the caller, used by one thread at a time, and reused from call to call so
/// that hot loops do not allocate. Systems with more scratch derive from it.
struct DynamicsWorkspace {
  virtual ~DynamicsWorkspace() = default;
  InputMatrix input;  ///< b(x, u) for the noise columns
};

/// A continuous-time system. Implementations are immutable once built and safe to share between
/// threads; all scratch space belongs to the caller (DynamicsWorkspace).
///
/// Each evaluation comes in two forms: with the caller's workspace (the one hot loops use), and
/// without, which makes a temporary workspace (convenient, and free for systems without scratch).
/// A system without scratch implements the forms without a workspace; a system with scratch overrides
/// make_workspace() and the forms with a workspace, and implements the others through them.
class Dynamics {
 public:
  virtual ~Dynamics() = default;

  /// The system's registry name, e.g. "cartpole" (docs/formats.md#systems-and-their-names).
  virtual const std::string& name() const = 0;
  /// States in their fixed order, with units.
  virtual const std::vector<Quantity>& states() const = 0;
  /// Controls in their fixed order, with units.
  virtual const std::vector<Quantity>& controls() const = 0;
  /// The physical parameters with their current values.
  virtual std::vector<Parameter> parameters() const = 0;

  int state_dim() const { return static_cast<int>(states().size()); }
  int control_dim() const { return static_cast<int>(controls().size()); }

  /// A workspace for this system's evaluations (the default holds the noise's input matrix).
  virtual std::unique_ptr<DynamicsWorkspace> make_workspace() const;

  /// xdot = f(x, u). When `jacobians` is not null, also fx and fu (resized if needed).
  virtual void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                        DynamicsJacobians* jacobians = nullptr) const = 0;
  /// The same with the caller's workspace (from make_workspace()).
  virtual void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot, DynamicsJacobians* jacobians,
                        DynamicsWorkspace& workspace) const;

  /// Convenience: returns f(x, u).
  Vector f(const VectorCRef& x, const VectorCRef& u) const;

  /// b(x, u) = df/du and its derivatives. The default differentiates fu from evaluate() by central
  /// differences (step 1e-6 scaled by the magnitude); systems with analytic forms override it.
  virtual void input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out) const;
  /// The same with the caller's workspace; the default calls the form without one.
  virtual void input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out,
                            DynamicsWorkspace& workspace) const;

  /// The noise model behind F(x, u); see ActuatorNoise for the columns it produces.
  const ActuatorNoise& noise_model() const { return noise_; }
  /// Replaces the noise model (validated against this system's dimensions).
  void set_noise_model(ActuatorNoise noise);
  /// Number of noise columns p.
  int noise_dim() const { return noise_.column_count(); }

  /// F(x, u) (n x p) and, when `derivatives` is true, the derivative of every column.
  void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
             DynamicsWorkspace& workspace) const;
  /// The same with a temporary workspace.
  void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives) const;

  /// The name, states and controls: what a measurement file must match.
  SystemSignature signature() const { return {name(), states(), controls()}; }

 protected:
  /// b and its derivatives by central differences of fu (the default input_matrix), evaluating with
  /// `workspace` when not null.
  void input_matrix_by_differences(const VectorCRef& x, const VectorCRef& u, InputMatrix& out,
                                   DynamicsWorkspace* workspace) const;

 private:
  ActuatorNoise noise_;
};

using DynamicsPtr = std::shared_ptr<const Dynamics>;

}  // namespace gpilqg
