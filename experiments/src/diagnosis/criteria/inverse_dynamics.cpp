#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gpilqg/experiments/diagnosis/accelerations.hpp"
#include "gpilqg/experiments/diagnosis/derivative_window.hpp"
#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/instrumental_variables.hpp"
#include "gpilqg/experiments/diagnosis/residual_analysis.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"

namespace gpilqg::diagnosis {

std::shared_ptr<const InverseDynamicsCriterion> InverseDynamicsCriterion::make(FitContext& c) {
  std::shared_ptr<InverseDynamicsCriterion> out(new InverseDynamicsCriterion());
  if (c.data == nullptr) return out;
  const Transitions& data = *c.data;
  const ForceComponents components = force_components(*c.model.build());
  const auto k = static_cast<Eigen::Index>(components.forces.size());
  const AccelerationEstimate estimate = estimate_accelerations(data, components.velocity_states(), c.dt);
  out->accelerations_ = std::make_shared<const Matrix>(estimate.qdd);
  out->reach_ = estimate.window / 2;
  // Parallel filtering: the controls and the model's forces seen through the acceleration
  // estimate's weights (accelerations.hpp, force_residual).
  out->filter_ = estimate.filter();
  const std::vector<int> rows = all_rows(data);
  const ForceResidualParts parts = out->force_residual_parts(c.model, data, rows);
  out->standstill_ = std::make_shared<const Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>>(
      standstill_rows(data, components.velocity_states(), out->filter_));
  for (Eigen::Index i = 0; i < k; ++i) out->standstill_counts_.push_back(static_cast<long>(out->standstill_->col(i).count()));
  c.residual = parts.inertial - parts.forces;
  out->leave_out_standstill(c.residual, rows);
  // The model's own force W_v^-1 f_v, as the residual sees it, on the equations the criterion has.
  Matrix own = parts.forces;
  out->leave_out_standstill(own, rows);
  out->own_force_ = std::make_shared<const Matrix>(std::move(own));
  // IDIM-WLS (Gautier): w_i = 1 / sigma_i^2 with sigma_i^2 the larger of component i's white noise
  // (noise_i, from its repeated differences within each run of rows where the coordinate moves: the
  // noise of the torque and of the acceleration estimate) and the mean square of its residual on the
  // training rows where it moves (left_i: what the model as given leaves of that joint's equations). Each joint's equations then count by how
  // well the model can be expected to fit them, not by how quiet its sensor is: a joint whose sensor
  // is quiet but whose model is wrong by far more does not drown the others. The noise is taken from
  // the residual with the controls and forces as they are at each row: the filter turns their white
  // noise into a smooth one that differences no longer see, and it scales every component's noise
  // variance by the same |m|^2.
  const Matrix unfiltered = parts.inertial - parts.forces_at_rows;
  const std::vector<RowSegment> segments = row_segments(data);
  const std::vector<int> training = data.rows(false);
  c.weights.resize(k);
  out->noise_ = Vector(k);
  out->left_ = Vector(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    // Runs of equations: at a standstill a dry friction of the model flips with the velocity's noise,
    // which is no noise of the equations the criterion has. A coordinate that never moves keeps its
    // records whole (its equations are all left out; the level only has to exist).
    std::vector<Vector> pieces;
    for (const RowSegment& s : segments)
      for (int t = s.first; t < s.end;) {
        int end = t;
        while (end < s.end && !(*out->standstill_)(end, i)) ++end;
        if (end - t >= 3) pieces.push_back(unfiltered.col(i).segment(t, end - t));
        t = std::max(end, t) + 1;
      }
    if (pieces.empty())
      for (const RowSegment& s : segments) pieces.push_back(unfiltered.col(i).segment(s.first, s.end - s.first));
    const double rms = std::sqrt(unfiltered.col(i).squaredNorm() / std::max<double>(1.0, data.size()));
    out->noise_(i) = std::max(difference_noise_std(pieces), 1e-12 * (1.0 + rms));
    double square = 0.0;
    long moving = 0;
    for (int t : training) {
      square += c.residual(t, i) * c.residual(t, i);
      moving += (*out->standstill_)(t, i) ? 0 : 1;
    }
    out->left_(i) = std::sqrt(square / std::max(1.0, static_cast<double>(moving)));
    const double sigma = std::max(out->noise_(i), out->left_(i));
    c.weights(i) = 1.0 / (sigma * sigma);
  }
  return out;
}

std::shared_ptr<const InverseDynamicsCriterion> InverseDynamicsCriterion::with_instruments(const FitContext& c) const {
  std::shared_ptr<InverseDynamicsCriterion> out(new InverseDynamicsCriterion(*this));
  out->instruments_ = simulated_instruments(c);
  return out;
}

std::shared_ptr<const InverseDynamicsCriterion> InverseDynamicsCriterion::at_instruments() const {
  std::shared_ptr<InverseDynamicsCriterion> out(new InverseDynamicsCriterion(*this));
  if (instruments_) out->accelerations_ = instruments_->accelerations;
  out->filter_.window = 0;
  out->instruments_ = nullptr;
  return out;
}

std::string InverseDynamicsCriterion::name() const {
  return fit_criterion_name(kind()) + (instruments_ ? "-iv" : "");
}

InverseDynamicsCriterion::ForceResidualParts InverseDynamicsCriterion::force_residual_parts(
    const ModelSpec& model, const Transitions& data, const std::vector<int>& rows) const {
  const DynamicsPtr system = model.build();
  const Matrix u = applied_controls(data, model.input_delay);
  if (filter_.window == 0) {
    GeneralisedForceParts parts = generalised_force_parts(*system, data, u, *accelerations_, rows);
    ForceResidualParts out{std::move(parts.inertial), -parts.forces, Matrix()};
    out.forces_at_rows = out.forces;
    return out;
  }
  // Both terms at every row a window of `rows` reaches, from one evaluation per row; the forces
  // then seen through the weights.
  const GeneralisedForceParts parts = generalised_force_parts(*system, data, u, *accelerations_, all_rows(data));
  return {rows_of(parts.inertial, rows), -filtered_at(data, parts.forces, rows, filter_), -rows_of(parts.forces, rows)};
}

Matrix InverseDynamicsCriterion::force_residual(const ModelSpec& model, const Transitions& data,
                                                const std::vector<int>& rows) const {
  const ForceResidualParts parts = force_residual_parts(model, data, rows);
  Matrix r = parts.inertial - parts.forces;
  leave_out_standstill(r, rows);
  return r;
}

Matrix InverseDynamicsCriterion::filtered(const Transitions& data, const Matrix& y, const std::vector<int>& rows) const {
  Matrix seen = filter_.window > 0 ? filtered_at(data, y, rows, filter_) : rows_of(y, rows);
  leave_out_standstill(seen, rows);
  return seen;
}

void InverseDynamicsCriterion::leave_out_standstill(Matrix& y, const std::vector<int>& rows) const {
  if (!standstill_ || standstill_->cols() == 0 || rows.empty()) return;
  const Eigen::Index k = standstill_->cols();
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int t = rows[r];
    for (Eigen::Index j = 0; j < y.cols(); ++j)
      if ((*standstill_)(t, j % k)) y(static_cast<Eigen::Index>(r), j) = 0.0;
  }
}

Matrix InverseDynamicsCriterion::residual(const ModelSpec& model, const FitContext& c, int* diverged) const {
  if (diverged != nullptr) *diverged = 0;
  return force_residual(model, *c.data, all_rows(*c.data));
}

Vector InverseDynamicsCriterion::weighted_residual(const ModelSpec& model, const FitContext& c,
                                                   const std::vector<int>& rows, bool*) const {
  const Matrix r = force_residual(model, *c.data, rows);
  const Vector sqrt_w = c.weights.cwiseSqrt();
  const auto k = static_cast<Eigen::Index>(sqrt_w.size());
  Vector out(static_cast<Eigen::Index>(rows.size()) * k);
  for (Eigen::Index i = 0; i < r.rows(); ++i) out.segment(i * k, k) = sqrt_w.cwiseProduct(r.row(i).transpose());
  return out;
}

std::vector<int> InverseDynamicsCriterion::scale_channels(const FitContext& c) const {
  if (!own_force_) return Criterion::scale_channels(c);
  std::vector<int> channels(static_cast<std::size_t>(c.weights.size()));
  for (std::size_t i = 0; i < channels.size(); ++i) channels[i] = static_cast<int>(i);
  return channels;
}

double InverseDynamicsCriterion::own_change(const FitContext& c, int row, int channel) const {
  if (!own_force_) return Criterion::own_change(c, row, channel);
  return (*own_force_)(row, channel);
}

std::vector<std::string> InverseDynamicsCriterion::unidentifiable(const std::vector<LibraryEffect>& candidates) const {
  std::vector<std::string> out;
  for (const LibraryEffect& effect : candidates) {
    const bool gain = effect.kind == EffectKind::ActuatorGain ||
                      (effect.kind == EffectKind::Recalibration &&
                       (effect.recalibrated.ends_with(".gain") || effect.recalibrated.ends_with(".gear")));
    if (gain) out.push_back(effect.name);
  }
  return out;
}

std::string InverseDynamicsCriterion::unidentifiable_reason() const {
  return "the force residual and the inertias scale with them";
}

double InverseDynamicsCriterion::flexible_share(const ModelSpec& model, const OneStepGp*, const FitContext& c,
                                                const GpSettings& settings) const {
  const Matrix force = residual(model, c);
  // The GP of what the model leaves learns the equations the criterion has: not the rows at standstill,
  // where the residual is zero by definition and a GP trained or scored there would be charged for it.
  return weighted_heldout_explained(*c.data, force, gp_column_means(*c.data, force, settings, standstill_.get()),
                                    c.weights);
}

std::string InverseDynamicsCriterion::description(double, int) const {
  std::string out =
      fmt::format("criterion: inverse dynamics, the generalised-force residual M(q) qdd - h(q, qdot, u) with qdd a "
                  "zero-phase {}",
                  filter_.derivative == 2 ? "second derivative of the measured positions (the velocities were estimated)"
                                          : "derivative of the measured velocities");
  if (filter_.window > 0)
    out += fmt::format(" (Savitzky-Golay window of {} samples, the controls and the model's forces seen through the same "
                       "weights)", filter_.window);
  if (noise_.size() > 0) {
    std::string noise, left;
    for (Eigen::Index i = 0; i < noise_.size(); ++i) {
      noise += fmt::format("{}{:.3g}", i == 0 ? "" : ", ", noise_(i));
      left += fmt::format("{}{:.3g}", i == 0 ? "" : ", ", left_(i));
    }
    out += fmt::format("\n   weights (IDIM-WLS): each force component by 1 / max(noise, rms left by the model as given)^2, "
                       "noise [{}], left [{}]", noise, left);
    long still = 0;
    for (const long n : standstill_counts_) still += n;
    if (still > 0)
      out += fmt::format("\n   left out where the coordinate stands still (a static friction holds it with any force up to "
                         "its breakaway): [{}] rows of {} per component",
                         fmt::join(standstill_counts_, ", "), standstill_ ? standstill_->rows() : 0);
  }
  if (instruments_)
    out += fmt::format("\n   instrumental variables (IDIM-IV): instruments from the model simulated over windows of {} "
                       "samples from measured states, {} of {} rows instrumented{}",
                       instruments_->window, instruments_->instrumented_rows(), instruments_->instrumented.size(),
                       instruments_->restarts > 0 ? fmt::format(", {} restarts after a diverged state", instruments_->restarts)
                                                  : "");
  return out;
}

}  // namespace gpilqg::diagnosis
