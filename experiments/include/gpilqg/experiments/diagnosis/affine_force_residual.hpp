#pragma once
/// @file affine_force_residual.hpp
/// The inverse-dynamics residual of a model with force effects linear in their parameters, in closed
/// form: what makes their fits one least-squares solve on a regressor evaluated once per sample.
///
/// A force effect adds W(x) Q_e(x, u; theta_e) to xdot (effects.hpp), and W_v^-1 W_v = I on the
/// force components, so the generalised-force residual (generalised_force_residual.hpp) of the model
/// with the effect is the residual without it minus the effect's force,
///
///   r_t(theta) = W_v^-1 (qdd_t - f_v(x_t, u_t) - W_v Q_e) = r_t^0 - Q_e(x_t, u_t; theta):
///
/// M(q) and h(q, qdot, u) do not move with theta. For effects whose force is linear in their
/// parameters (LinearForceEffect: joint viscous damping, Coulomb friction at a fixed v0, constant and
/// external forces; user basis forces), Q_e = sum_j theta_j g_j(x, u), and for a set of them with the
/// parameters stacked, theta = [theta_1; ...; theta_E] (p in all),
///
///   r_t(theta) = r_t(theta_0) - G_t (theta - theta_0),   G_t = [g_1(x_t, u_t), ..., g_p(x_t, u_t)]  (k x p),
///
/// exactly, from any theta_0. Weighted like every criterion residual, row by row sqrt(w_i) r_{t,i}
/// (w_i = 1 / sigma_i^2, FitContext::weights) and stacked over rows (index t k + i). The regressor of
/// effect_fit.hpp, d phi / d theta = -(d r / d theta), is then sqrt(w) G itself: no finite
/// differences, and the Gauss-Newton step from any theta is the least-squares solution.
///
/// Cost: one evaluation of the model's residual at theta_0 (M and h once per sample) and each
/// effect's force once per sample and parameter; every r(theta) after that is a matrix-vector product.
///
/// Parameters of the model itself can enter the inverse dynamics linearly too: M(q) qdd + c(q, qdot)
/// is linear in each body's standard inertial parameters (its mass, first moments and inertia tensor;
/// MuJoCo's mass recalibration scales the mass and the inertia together at a fixed centre of mass),
/// and the armature, joint damping and spring stiffness enter as forces. Their residual is the same
/// affine function, with the column -(d r / d theta_j) the secant of two evaluations. That they are
/// affine is not assumed: effect_fit.cpp checks it on the data (probed_affine_residual) and otherwise
/// uses the rebuilt model at every theta.

#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

namespace gpilqg::diagnosis {

/// True when every effect of `effects` is a force linear in its parameters (the closed form applies).
bool linear_forces(const std::vector<const LibraryEffect*>& effects);

/// sqrt(w_i) G_{t,ij} stacked over `rows` (index t k + i; rows.size() k x p): the forces' bases
/// g_j(x_t, u_t) for the effects of `effects` (linear_forces), in the model `model` (its system's
/// kinematics for forces at a body) driven by the measured inputs delayed by model.input_delay.
/// Under the inverse-dynamics criterion of `c` this is the regressor d phi / d theta of the effects.
Matrix weighted_force_regressor(const ModelSpec& model, const std::vector<const LibraryEffect*>& effects,
                                const FitContext& c, const std::vector<int>& rows);

/// r(theta) of the file comment at every row of c.data, weighted: built once, evaluated at any theta.
class AffineForceResidual {
 public:
  /// `model` has every effect of `effects` (linear_forces) at its slice of `theta0`, the stacked
  /// values. Evaluates its residual (weighted_residual_of) and the regressor at every row once.
  AffineForceResidual(const ModelSpec& model, const std::vector<const LibraryEffect*>& effects, const Vector& theta0,
                      const FitContext& c);
  /// The same from its pieces: `residual` sqrt(w) r(theta0) and `regressor` sqrt(w) G at every row
  /// (N k entries and N k x theta0.size()), `k` force components.
  AffineForceResidual(Vector theta0, Eigen::Index k, Vector residual, Matrix regressor);

  /// sqrt(w_i) r_{t,i}(theta) stacked over `rows` (index t k + i).
  Vector weighted(const VectorCRef& theta, const std::vector<int>& rows) const;
  /// sqrt(w) G stacked over `rows` (rows.size() k x p), the same at every theta.
  Matrix weighted_regressor(const std::vector<int>& rows) const;

 private:
  Vector theta0_;
  Eigen::Index k_ = 0;  ///< force components
  Vector residual_;     ///< sqrt(w) r(theta0) at every row (N k)
  Matrix regressor_;    ///< sqrt(w) G at every row (N k x p)
};

}  // namespace gpilqg::diagnosis
