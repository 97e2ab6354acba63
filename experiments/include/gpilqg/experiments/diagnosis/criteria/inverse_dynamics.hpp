#pragma once
/// @file inverse_dynamics.hpp
/// The inverse-dynamics criterion (IDIM-LS, Gautier; in its instrumental-variable form IDIM-IV,
/// instrumental_variables.hpp): the generalised force the model is missing,
///
///   r_t = W_v(x_t)^-1 (qdd_t - f_v(x_t, u_t)),
///
/// with qdd_t a zero-phase Savitzky-Golay derivative of the measured velocities (of the measured
/// positions, twice, when the velocities were estimated from them), one window for every coordinate
/// (accelerations.hpp), and the model's whole generalised force W_v^-1 f_v (the controls,
/// gravity, Coriolis, friction, every effect) seen through the same weights: parallel filtering
/// (Gautier 1997), which filters the torques and every column of the observation matrix with one
/// filter. The estimate is the window's mean acceleration; a force evaluated at the window's centre
/// alone would be compared with it, and a friction that changes sign within the window would look
/// like a smooth one as wide as the window (a Coulomb friction as a tanh of width |qdd| w dt / 2). Friction and offsets are linear and directly visible there, and an error in a torque
/// is not divided by the joint's inertia; it needs measured velocities and controls that are
/// generalised forces (generalised_force_residual.hpp).
///
/// The force residual M qdd - h(q, qdot, k u) is homogeneous in the inertias and the actuators'
/// gains together (the scale ambiguity that a measured torque fixes by its own calibration), so the
/// gains and gears are not candidates here.

#include <memory>

#include "gpilqg/experiments/diagnosis/accelerations.hpp"
#include "gpilqg/experiments/diagnosis/criteria/criterion.hpp"

namespace gpilqg::diagnosis {

struct Instruments;  // instrumental_variables.hpp

class InverseDynamicsCriterion final : public Criterion {
 public:
  /// Estimates the accelerations on c.data, finds the rows where a coordinate stands still
  /// (leave_out_standstill), and sets c.residual (N x k) to the force residual of c.model and
  /// c.weights to the IDIM-WLS weights 1 / sigma_i^2 (Gautier), sigma_i = max(noise_i, left_i):
  /// noise_i the white noise of component i's residual (its repeated differences within each record,
  /// with the controls as applied: what a smooth missing force does not raise), left_i the rms of its
  /// residual on the training rows where it moves (what the model as given leaves of joint i's
  /// equations). Throws std::invalid_argument on a system without a generalised-force map or records
  /// too short for the estimate.
  static std::shared_ptr<const InverseDynamicsCriterion> make(FitContext& c);

  /// The criterion with the same accelerations and instruments simulated from c.model
  /// (instrumental_variables.hpp): the IV form.
  std::shared_ptr<const InverseDynamicsCriterion> with_instruments(const FitContext& c) const;
  /// The criterion at the instruments' simulated data: their accelerations, the controls as applied
  /// (the simulated accelerations are the model's own at each state, not a window's mean), no
  /// instruments. Its regressor of a set of effects is the instrument matrix Z.
  std::shared_ptr<const InverseDynamicsCriterion> at_instruments() const;

  FitCriterion kind() const override { return FitCriterion::InverseDynamics; }
  std::string name() const override;

  /// The measured accelerations of the force components' velocity states (N x k).
  const Matrix& accelerations() const { return *accelerations_; }
  /// h, the half-width of the acceleration estimate's window (the rows one sample's noise reaches).
  int reach() const { return reach_; }
  /// The one window of the acceleration estimate; 0 at the instruments (controls as applied).
  int acceleration_window() const { return filter_.window; }
  /// The acceleration estimate's filter (window 0 at the instruments).
  const AccelerationFilter& acceleration_filter() const { return filter_; }
  /// Per force component: the white noise of its residual and the rms of its residual on the
  /// training rows, the two sides of its weight's sigma_i = max(noise_i, left_i) (make).
  const Vector& noise() const { return noise_; }
  const Vector& left() const { return left_; }
  /// The instruments of the IV form, or null for least squares.
  const Instruments* instruments() const { return instruments_.get(); }

  /// The force residual of `model` on `data` at `rows` (rows.size() x k): with the acceleration
  /// window w > 0 (parallel filtering, file comment)
  ///
  ///   r_t = M(q_t) qdd_t - sum_s m_s g_s,   g_s = W_v^-1 f_v(x_s, u_s) at every sample s of t's window,
  ///
  /// the model's generalised force (controls, gravity, Coriolis, friction and every effect) seen
  /// through the acceleration estimate's weights m (filtered_at), as the estimate sees the
  /// acceleration; at the instruments (w = 0), r_t = M qdd_t - g_t. The controls are the measured ones
  /// delayed by model.input_delay.
  Matrix force_residual(const ModelSpec& model, const Transitions& data, const std::vector<int>& rows) const;
  /// A per-sample quantity of `data`'s rows (N x c: the forces of an effect at the measured states)
  /// as force_residual sees it at `rows`: through the same weights, or as it is at w = 0, and left
  /// out where its component stands still (leave_out_standstill).
  Matrix filtered(const Transitions& data, const Matrix& y, const std::vector<int>& rows) const;
  /// Zeroes the entries of `y` (rows.size() x c, c a multiple of the k force components, column j k + i
  /// for component i) at the rows where component i's coordinate stands still in the measured data
  /// (standstill_rows, accelerations.hpp): a static friction's force there is anything within its
  /// breakaway force, so those equations are left out of every fit, score and noise level of the
  /// criterion, as robot identification leaves them out. force_residual and filtered do it.
  void leave_out_standstill(Matrix& y, const std::vector<int>& rows) const;
  /// Per force component: the rows left out as standing still.
  const std::vector<long>& standstill_counts() const { return standstill_counts_; }

  std::string scored_on() const override { return "the generalised-force (inverse-dynamics) residual"; }
  Matrix residual(const ModelSpec& model, const FitContext& c, int* diverged = nullptr) const override;
  Vector weighted_residual(const ModelSpec& model, const FitContext& c, const std::vector<int>& rows,
                           bool* finite = nullptr) const override;
  /// Every force component, against the model's own generalised force W_v^-1 f_v.
  std::vector<int> scale_channels(const FitContext& c) const override;
  double own_change(const FitContext& c, int row, int channel) const override;
  /// The actuators' gains and gears.
  std::vector<std::string> unidentifiable(const std::vector<LibraryEffect>& candidates) const override;
  std::string unidentifiable_reason() const override;
  bool needs_one_step_gp() const override { return false; }
  /// A GP of each component of `model`'s force residual on (x, u) is the flexible model.
  double flexible_share(const ModelSpec& model, const OneStepGp* gp, const FitContext& c,
                        const GpSettings& settings) const override;
  std::string starts() const override { return {}; }
  std::string description(double dt, int restarts) const override;
  const InverseDynamicsCriterion* inverse_dynamics() const override { return this; }

 private:
  InverseDynamicsCriterion() = default;

  /// The two terms of force_residual: M(q_t) qdd_t and the model's generalised force as seen; and
  /// that force as it is at the rows (W_v^-1 f_v(x_t, u_t), not seen through the weights).
  struct ForceResidualParts {
    Matrix inertial, forces, forces_at_rows;
  };
  ForceResidualParts force_residual_parts(const ModelSpec& model, const Transitions& data,
                                          const std::vector<int>& rows) const;

  std::shared_ptr<const Matrix> accelerations_;
  std::shared_ptr<const Matrix> own_force_;  ///< N x k, the base model's generalised force as the residual sees it
  int reach_ = 0;
  AccelerationFilter filter_;
  std::shared_ptr<const Instruments> instruments_;
  Vector noise_, left_;
  /// N x k, the measured data's rows at which each component's coordinate stands still (null: none).
  std::shared_ptr<const Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>> standstill_;
  std::vector<long> standstill_counts_;
};

}  // namespace gpilqg::diagnosis
