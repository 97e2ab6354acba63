#pragma once
/// @file fit_criterion.hpp
/// The error the candidate effects are fitted to and scored on (effect_fit.hpp). Three criteria, each
/// the practice of a field of system identification:
///
///  - one-step (equation error): the state one model step after the measured state,
///    e_t = x_{t+1} - phi(x_t, u_t). The default of least-squares identification of sampled models;
///    biased when the regressors (the measured states) are noisy or filtered (errors in variables), and
///    blind to effects whose one-step change is below the noise (simulation_error.hpp says why);
///  - simulation (output error, MATLAB's `oe`/`pem`): the state simulated from the measured state at
///    the start of a window of W samples (simulation_error.hpp);
///  - inverse-dynamics (IDIM-LS, Gautier; IDIM-IV, Janot et al.): the generalised force the model is
///    missing, r_t = W_v(x_t)^-1 (qdd_t - f_v(x_t, u_t)) with qdd_t from a zero-phase derivative of the
///    measured velocities (generalised_force_residual.hpp, accelerations.hpp). Friction and offsets are
///    linear and directly visible there, and an error in a torque is not divided by the joint's
///    inertia; it needs measured velocities and controls that are generalised forces.

#include <optional>
#include <string>
#include <string_view>

namespace gpilqg::diagnosis {

enum class FitCriterion {
  OneStep,          ///< "one-step"
  Simulation,       ///< "simulation", over windows of W samples
  InverseDynamics,  ///< "inverse-dynamics", the generalised-force residual
};

/// "one-step", "simulation" or "inverse-dynamics"; nullopt for any other name.
std::optional<FitCriterion> parse_fit_criterion(std::string_view name);
std::string fit_criterion_name(FitCriterion criterion);

}  // namespace gpilqg::diagnosis
