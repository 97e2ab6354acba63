#pragma once
/// @file cost.hpp
/// Stage and terminal costs with their first and second derivatives (paper eq. for J(x_0): the total
/// cost l_T(x_T) + sum_t l(x_t, u_t)).
///
/// QuadraticCost is the cost of docs/formats.md#problem-config-gpilqg-solve-and-gpilqg-plan and of the
/// reference problem, with an optional time-varying reference (tracking):
///
///   l_t(x, u) = dt (0.5 e' Q e + 0.5 d' R d),   e = x - x_ref(t),  d = u - u_ref(t)
///   l_T(x)    = 0.5 e' Qf e,                    e = x - x_ref(T)
///
///   l_x = dt Q e,  l_u = dt R d,  l_xx = dt Q,  l_uu = dt R,  l_ux = 0;   terminal: Qf e, Qf.
/// Q, R and Qf are symmetric (validated); Q and Qf positive semidefinite, R positive definite is the
/// caller's choice (the solver regularises).

#include <memory>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// Value and derivatives of a stage cost. For a terminal cost, lu, luu and lux are left empty.
struct CostDerivatives {
  double value = 0.0;
  Vector lx;   ///< n
  Vector lu;   ///< m
  Matrix lxx;  ///< n x n
  Matrix luu;  ///< m x m
  Matrix lux;  ///< m x n
  void resize(int n, int m);
};

/// The scratch space of one caller of a Cost (Crocoddyl's model/data split, as StepWorkspace is for a
/// StepModel): made by the cost's make_workspace(), owned by the caller, used by one thread at a time
/// and reused from call to call, so that a solver's passes do not allocate. Costs with scratch (the
/// expected cost of a belief, which evaluates the state cost first) derive from it.
struct CostWorkspace {
  virtual ~CostWorkspace() = default;
};

/// A cost over a horizon of T steps: stages t = 0..T-1 and a terminal cost at T. Immutable once built
/// and shareable between threads; all scratch space belongs to the caller. Each evaluation is one
/// virtual call with the caller's workspace (from make_workspace()), which implementations override;
/// the form without a workspace is a convenience that makes a temporary one (free for costs without
/// scratch). An implementation brings those forms into its scope with `using Cost::stage;` etc.
class Cost {
 public:
  virtual ~Cost() = default;
  virtual int state_dim() const = 0;
  virtual int control_dim() const = 0;

  /// A workspace for this cost's evaluations (the default is empty).
  virtual std::unique_ptr<CostWorkspace> make_workspace() const { return std::make_unique<CostWorkspace>(); }

  /// l_t(x, u); fills `derivatives` when not null.
  virtual double stage(int t, const VectorCRef& x, const VectorCRef& u, CostDerivatives* derivatives,
                       CostWorkspace& workspace) const = 0;
  /// l_T(x); fills lx and lxx of `derivatives` when not null.
  virtual double terminal(const VectorCRef& x, CostDerivatives* derivatives, CostWorkspace& workspace) const = 0;
  /// The terminal cost of a horizon that ends at step t (used by receding-horizon windows); the
  /// default ignores t.
  virtual double terminal_at(int t, const VectorCRef& x, CostDerivatives* derivatives,
                             CostWorkspace& workspace) const {
    (void)t;
    return terminal(x, derivatives, workspace);
  }

  /// The same with a temporary workspace.
  double stage(int t, const VectorCRef& x, const VectorCRef& u, CostDerivatives* derivatives = nullptr) const;
  double terminal(const VectorCRef& x, CostDerivatives* derivatives = nullptr) const;
  double terminal_at(int t, const VectorCRef& x, CostDerivatives* derivatives = nullptr) const;
};

class QuadraticCost final : public Cost {
 public:
  /// Regulation to a fixed goal with u_ref = 0. Throws std::invalid_argument naming the field when a
  /// size does not match or a weight matrix is not symmetric or not finite.
  QuadraticCost(double dt, Matrix Q, Matrix R, Matrix Qf, Vector goal);

  /// Tracking of a reference: x_ref has T+1 columns (n x (T+1)), u_ref T columns (m x T).
  static QuadraticCost tracking(double dt, Matrix Q, Matrix R, Matrix Qf, Matrix x_ref, Matrix u_ref);

  int state_dim() const override { return static_cast<int>(Q_.rows()); }
  int control_dim() const override { return static_cast<int>(R_.rows()); }
  using Cost::stage;
  using Cost::terminal;
  using Cost::terminal_at;
  double stage(int t, const VectorCRef& x, const VectorCRef& u, CostDerivatives* derivatives,
               CostWorkspace& workspace) const override;
  double terminal(const VectorCRef& x, CostDerivatives* derivatives, CostWorkspace& workspace) const override;
  /// 0.5 e' Qf e with e = x - x_ref(t) (the reference held at its final value past its end).
  double terminal_at(int t, const VectorCRef& x, CostDerivatives* derivatives,
                     CostWorkspace& workspace) const override;

  /// The state reference at step t (the goal when regulating). Past the end of a tracking reference
  /// its final value is held, so receding-horizon windows may extend beyond the task. t < 0 throws.
  Eigen::Ref<const Vector> state_reference(int t) const;
  /// The control reference at step t (zero when regulating), held at its final value past the end.
  Eigen::Ref<const Vector> control_reference(int t) const;
  /// Number of stages of a tracking reference (0 when regulating).
  int reference_horizon() const { return tracking_ ? static_cast<int>(u_ref_.cols()) : 0; }

 private:
  QuadraticCost(double dt, Matrix Q, Matrix R, Matrix Qf, Matrix x_ref, Matrix u_ref, bool tracking);

  double dt_;
  Matrix Q_, R_, Qf_;
  Matrix x_ref_;  ///< n x 1 (regulation) or n x (T+1) (tracking)
  Matrix u_ref_;  ///< m x 1 (regulation) or m x T (tracking)
  bool tracking_;
};

/// Straight-line reference from x0 to goal over T steps: x_ref(t) = x0 + (t/T)(goal - x0) for
/// t = 0..T (n x (T+1)). The paper's quadrotor tasks track such a line.
Matrix straight_line_reference(const VectorCRef& x0, const VectorCRef& goal, int horizon);

}  // namespace gpilqg
