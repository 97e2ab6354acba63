#pragma once
/// @file generalised_force_residual.hpp
/// The inverse-dynamics residual of a model: the generalised force that the model is missing at every
/// measured sample, the quantity robot identification fits friction and parameters to (IDIM-LS,
/// Gautier; IDIM-IV, Janot, Gautier et al.).
///
/// A mechanical system with a generalised-force map (generalised_forces.hpp) moves by
///
///   M(q) qdd = h(q, qdot, u) + Q,    i.e.  xdot = f(x, u) + W(x) Q,  W = [0; M^-1] on the velocity rows.
///
/// With W_v (k x k) the rows of W at the velocity states of the k force components (in the order of
/// generalised_forces()), f_v the same rows of the model's f, and qdd_t the measured acceleration of
/// those velocity states (accelerations.hpp), the residual of row t is
///
///   r_t = W_v(x_t)^-1 (qdd_t - f_v(x_t, u_t)).
///
/// For a MuJoCo model or the cart-pole W_v^-1 = M(q), so r_t = M qdd_t - h(q, qdot, u_t): the measured
/// inverse dynamics minus the model's forces, and with controls that are generalised forces
/// (actuated joints, gear 1) the classical torque residual tau_measured - ID(q, qdot, qdd). If the
/// world is the model plus a force Q_e(x, u) that the model lacks and the data are noise-free,
/// r_t = Q_e(x_t, u_t) up to the error of the acceleration estimate, multiplied by W_v^-1; friction
/// and offsets therefore enter r linearly in their parameters, whatever the inertia.
///
/// Assumptions.
/// - The controls are the ones the model applies: u_t is the measured input delayed by the model's
///   input delay (ModelSpec::input_delay, applied_controls), and the model's actuator gain and
///   actuator map turn it into forces (so commanded motor currents work as well as torques, when the
///   model maps them).
/// - The velocities are measured (the accelerations come from them, never from the positions), and
///   every force component acts on one velocity state (W is zero outside the velocity rows of the
///   components, as W = [0; M^-1] is).
/// - The model is evaluated at the measured state x_t as it is: no filtering of x or u here.
///
/// Cost: where the system computes its inverse dynamics directly (GeneralisedForceInput::
/// inverse_dynamics: a MuJoCo model), that and the effects' forces per row,
/// r_t = ID(x_t, k u_t, qdd_t) - Q_e(x_t, u_t) (k the actuator gain): for MuJoCo without constraint
/// rows the position and velocity stages and one product with M, no factorisation; with them one
/// forward pass and one product with M. Elsewhere one evaluation of
/// f and of W per row, in one workspace each per call, and one k x k factorisation per row. Both are
/// the same r_t up to rounding (tests/experiments/inverse_dynamics_test.cpp compares them).

#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/generalised_forces.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"

namespace gpilqg::diagnosis {

/// The generalised-force components of a model and the coordinate each acts on, in the order of
/// generalised_forces(): the columns of the residual.
struct ForceComponents {
  std::vector<Quantity> forces;                     ///< k names with units, e.g. Q_x [N], Q_theta [N m]
  std::vector<GeneralisedCoordinate> coordinates;   ///< k, coordinates[i].component == i
  /// The state column of each component's velocity, coordinates[i].velocity: the columns to differentiate
  /// (estimate_accelerations) for the residual.
  std::vector<int> velocity_states() const;
};

/// The components of `model` (a system with a generalised-force map, or an EffectDynamics over one,
/// whose map is its base system's). Throws std::invalid_argument naming the system when it has no
/// generalised-force map, or naming the component that acts on no coordinate of the state.
ForceComponents force_components(const Dynamics& model);

/// The system whose generalised-force map `model` uses: `model` itself, or the base of an
/// EffectDynamics (effects add their forces through the base's map). Its workspaces are the ones a
/// ForceEffect::add_force takes. Throws std::invalid_argument naming the system when it has no
/// generalised-force map.
const Dynamics& force_map_system(const Dynamics& model);
/// The same, or null when `model` has no generalised-force map.
const Dynamics* force_map_owner(const Dynamics& model);

/// r_t (file comment) for the rows `rows` of `data` (rows.size() x k, in the order of `rows`):
/// `applied_u` the inputs the model applies at every row of data (N x m, applied_controls) and
/// `accelerations` the measured accelerations of every row of data (N x k, column i that of
/// force_components(model).coordinates[i].velocity, e.g. AccelerationEstimate::qdd for
/// velocity_states()). Throws std::invalid_argument for a model without a generalised-force map, wrong
/// sizes, a row outside data, or a row at which W_v is singular or f is not finite (naming the row).
Matrix generalised_force_residual(const Dynamics& model, const Transitions& data, const Matrix& applied_u,
                                  const Matrix& accelerations, const std::vector<int>& rows);

/// r_t in its two terms, r_t = inertial_t + forces_t: inertial_t = W_v^-1 qdd_t (M(q) qdd_t, the
/// term linear in the accelerations) and forces_t = -W_v^-1 f_v(x_t, u_t) (the residual at zero
/// acceleration: minus the model's generalised force, effects included), from one evaluation of the
/// model per row. Same arguments and errors as generalised_force_residual.
struct GeneralisedForceParts {
  Matrix inertial, forces;
};
GeneralisedForceParts generalised_force_parts(const Dynamics& model, const Transitions& data, const Matrix& applied_u,
                                              const Matrix& accelerations, const std::vector<int>& rows);

/// The same for a model description: model.build(), driven by the measured inputs delayed by
/// model.input_delay.
Matrix generalised_force_residual(const ModelSpec& model, const Transitions& data, const Matrix& accelerations,
                                  const std::vector<int>& rows);

/// The same with the controls given (N x m, one row per transition): force_controls of effect_fit.hpp,
/// the applied controls seen through the acceleration estimate's filter (accelerations.hpp).
Matrix generalised_force_residual(const ModelSpec& model, const Transitions& data, const Matrix& controls,
                                  const Matrix& accelerations, const std::vector<int>& rows);

}  // namespace gpilqg::diagnosis
