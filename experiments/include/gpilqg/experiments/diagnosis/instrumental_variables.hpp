#pragma once
/// @file instrumental_variables.hpp
/// The instrumental-variable form of the inverse-dynamics criterion (IDIM-IV: Janot, Vandanjon,
/// Gautier, "A generic instrumental variable approach for industrial robot identification", IEEE
/// TCST 2014): instruments from the simulated model remove the bias that the noise of the measured
/// velocities and accelerations puts into a least-squares fit of the force residual.
///
/// The bias. The residual of row t (generalised_force_residual.hpp) is linear in the parameters of a
/// force effect, r_t(theta) = r_t^0 - G(x_t) theta (affine_force_residual.hpp), but G is evaluated at
/// the *measured* state: for viscous friction G = -qdot_measured = -(qdot + e). Least squares solves
/// G' r(theta) = 0, and E[G' G] holds sum e^2 beside sum qdot^2, so the estimate shrinks by the factor
/// var(qdot) / (var(qdot) + sigma_e^2) however long the record (errors in variables; the same for the
/// inertial parameters and the noise of the acceleration estimate).
///
/// Instruments. Z_t = G(x_hat_t): the same regressor at the states x_hat_t of the model simulated
/// from the data, driven by the measured controls (the model's input delay applied), restarted from
/// the measured state at the start of every window of W samples (and after a divergence). Within a
/// window x_hat_t depends on the measured state at the window's start s and on the controls
/// u_s .. u_{t-1}, not on the noise of the samples around t; the accelerations of the instrument rows
/// are the backward differences of the simulated velocities, (v_hat_t - v_hat_{t-1}) / dt, which do not
/// involve u_t either (the torque whose noise is in r_t). Rows closer than the acceleration estimate's
/// reach h (the half-width of its widest Savitzky-Golay window, accelerations.hpp) to their window's
/// start share noise with that measured start. So the model is simulated over two grids of windows of
/// W = 4 (h + 1) samples, the second shifted by W / 2, and each row takes its instrument from the
/// window that started more than h rows before it, the later one when both did: every row but the
/// first h + 1 of a segment has an instrument (the others have Z_t = 0), and the simulation drifts
/// from the data for at most W samples. (Dropping the first rows of a single grid instead would leave
/// a row mask periodic in W, which can lock onto a period of the motion and weight it unevenly.)
///
/// The estimate. The IV estimate solves Z' r(theta) = 0 (as many instruments as parameters). With Q an
/// orthonormal basis of Z's columns this is the minimum of |Q' r(theta)|^2 = r' P_Z r, so the
/// Gauss-Newton fit of effect_fit.hpp runs unchanged on the projected residual Q' r and regressor Q' J
/// (one step for forces linear in their parameters). Its covariance is s^2 (Z'J)^-1 Z'Z (J'Z)^-1 =
/// s^2 (Q'J)^-1 (J'Q)^-1 with s^2 = |r|^2 / (N - p), widened to the delete-one-episode jackknife of the
/// same equations; with Z = J both reduce to least squares. The instruments are made once from the
/// model the effects are added to (their relevance, not their validity, depends on how good it is).

#include <memory>
#include <vector>

#include <algorithm>

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

namespace gpilqg::diagnosis {

/// The simulated data the instruments are evaluated at (file comment).
struct Instruments {
  /// The rows of the fit's data with x replaced by x_hat_t (x_next by x_hat_{t+1}); u, t, episode and
  /// heldout unchanged.
  Transitions data;
  /// N x k: the backward differences of the simulated velocities of the force components.
  std::shared_ptr<const Matrix> accelerations;
  /// N: whether row t has an instrument (more than h rows after the start of one of its windows).
  std::vector<bool> instrumented;
  int window = 0;  ///< W = 4 (h + 1), of each of the two grids
  int reach = 0;   ///< h
  int restarts = 0;  ///< simulated states that diverged, each followed by a restart from the measurement

  /// The rows with an instrument (true entries of `instrumented`).
  long instrumented_rows() const { return static_cast<long>(std::count(instrumented.begin(), instrumented.end(), true)); }
};

/// The instruments of an inverse-dynamics context (criterion_context with FitCriterion::InverseDynamics):
/// its model simulated over two staggered grids of windows of 4 (h + 1) rows, h the criterion's
/// reach (InverseDynamicsCriterion::reach). Throws
/// std::invalid_argument when the context is not inverse dynamics or has no data.
std::shared_ptr<const Instruments> simulated_instruments(const FitContext& context);

/// `context` at the data and accelerations of its criterion's instruments
/// (InverseDynamicsCriterion::at_instruments): the context in which the regressor of a set of effects
/// is its instrument matrix Z (rows without an instrument still to be zeroed, instrument_basis).
/// Throws std::invalid_argument when the context's criterion has no instruments.
FitContext instrument_context(const FitContext& context);

/// Z (stacked like the weighted regressor over `rows`, index t k + i) with the rows of the samples
/// without an instrument set to zero.
void zero_uninstrumented(Matrix& Z, const Instruments& instruments, const std::vector<int>& rows);

/// Q, an orthonormal basis of the columns of Z (Z's rows stacked like the weighted regressor over
/// `rows`, index t k + i), after zeroing the rows without an instrument. Empty when Z has a column of
/// zeros or is rank-deficient (no instrument for a parameter): the caller falls back to least squares.
Matrix instrument_basis(Matrix Z, const Instruments& instruments, const std::vector<int>& rows);

}  // namespace gpilqg::diagnosis
