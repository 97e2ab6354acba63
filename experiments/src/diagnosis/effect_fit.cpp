#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <atomic>
#include <chrono>
#include <iterator>
#include <map>
#include <mutex>
#include <optional>
#include <tuple>

#include <fmt/format.h>
#include <stdexcept>

#include <Eigen/Dense>

#include "gpilqg/core/fork_join.hpp"
#include "gpilqg/core/generalised_forces.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/experiments/diagnosis/affine_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/delay_start.hpp"
#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/instrumental_variables.hpp"
#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"
#include "gpilqg/experiments/diagnosis/student_t.hpp"
#include "set_residual.hpp"

namespace gpilqg::diagnosis {

std::shared_ptr<const StepModel> make_step_model(const ModelSpec& model, Integrator integrator, double dt, int substeps) {
  return gpilqg::make_step_model(model.build(), integrator, dt, substeps);
}

Matrix model_predictions(const ModelSpec& model, const FitContext& settings, int* diverged) {
  return settings.criterion->predictions(model, settings, diverged);
}

Matrix criterion_residual(const ModelSpec& model, const FitContext& settings, int* diverged) {
  return settings.criterion->residual(model, settings, diverged);
}

Vector weighted_residual_of(const ModelSpec& model, const FitContext& settings, const std::vector<int>& rows) {
  return settings.criterion->weighted_residual(model, settings, rows);
}

namespace {

Vector weighted_model_residual(const FitContext& c, const std::vector<int>& rows) {
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Vector sqrt_w = c.weights.cwiseSqrt();
  Vector out(static_cast<Eigen::Index>(rows.size()) * n);
  for (std::size_t k = 0; k < rows.size(); ++k)
    out.segment(static_cast<Eigen::Index>(k) * n, n) = sqrt_w.cwiseProduct(c.residual.row(rows[k]).transpose());
  return out;
}

Vector clamp_to(const Vector& theta, const Vector& lo, const Vector& hi) { return theta.cwiseMax(lo).cwiseMin(hi); }

/// The batch length of the significance test: context.batch when set, else ceil(sqrt(N)) of the N
/// held-out rows (at least 10), the classical batch-means rule: batches grow with the record, so the
/// serial correlation of a long record sampled fast (1 kHz) stays inside a batch. Rounded up to whole
/// windows of the simulation criterion.
int heldout_batch_length(const FitContext& c, int rows) {
  const int batch = c.batch > 0 ? c.batch : std::max(10, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(rows)))));
  // Whole windows under the simulation criterion: the errors within a window are strongly correlated.
  const int window = c.criterion->window();
  return (batch + window - 1) / window * window;
}

/// Held-out scores of theta_hat against the model (step 4).
void score_heldout(const SetResidual& residual, const Vector& theta, const FitContext& c, EffectFit& fit) {
  const std::vector<int> rows = c.data->rows(true);
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Vector before = weighted_model_residual(c, rows);
  const Vector after = residual.at(theta, rows);
  const Vector sqrt_w = c.weights.cwiseSqrt();
  fit.heldout_rmse_before = Vector::Zero(n);
  fit.heldout_rmse_after = Vector::Zero(n);
  // Batches of consecutive samples of one episode: per channel, sums of the reduction d and of the
  // "before" term.
  std::vector<Vector> d_batches, b_batches;
  Vector equations = Vector::Zero(n);  // per channel: the rows that are equations of the criterion (not 0 = 0)
  int previous_episode = -1, in_batch = 0;
  const int batch = heldout_batch_length(c, static_cast<int>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto seg = static_cast<Eigen::Index>(k) * n;
    const Vector rb = before.segment(seg, n), ra = after.segment(seg, n);
    fit.heldout_rmse_before += rb.cwiseQuotient(sqrt_w).cwiseAbs2();
    fit.heldout_rmse_after += ra.cwiseQuotient(sqrt_w).cwiseAbs2();
    for (Eigen::Index i = 0; i < n; ++i) equations(i) += rb(i) != 0.0 || ra(i) != 0.0 ? 1.0 : 0.0;
    const int episode = c.data->episode[static_cast<std::size_t>(rows[k])];
    if (episode != previous_episode || in_batch == batch) {
      d_batches.push_back(Vector::Zero(n));
      b_batches.push_back(Vector::Zero(n));
      in_batch = 0;
      previous_episode = episode;
    }
    b_batches.back() += rb.cwiseAbs2();
    d_batches.back() += rb.cwiseAbs2() - ra.cwiseAbs2();
    ++in_batch;
  }
  const Vector count = equations.cwiseMax(1.0);
  fit.heldout_rmse_before = fit.heldout_rmse_before.cwiseQuotient(count).cwiseSqrt();
  fit.heldout_rmse_after = fit.heldout_rmse_after.cwiseQuotient(count).cwiseSqrt();
  const auto K = static_cast<Eigen::Index>(b_batches.size());
  fit.heldout_channel_before.resize(K, n);
  fit.heldout_channel_reduction.resize(K, n);
  for (Eigen::Index b = 0; b < K; ++b) {
    fit.heldout_channel_before.row(b) = b_batches[static_cast<std::size_t>(b)].transpose();
    fit.heldout_channel_reduction.row(b) = d_batches[static_cast<std::size_t>(b)].transpose();
  }
  if (K >= 2) {
    fit.heldout_batch_before = fit.heldout_channel_before.rowwise().sum();
    fit.heldout_batch_reduction = fit.heldout_channel_reduction.rowwise().sum();
  }
  // On every channel: the ratio estimator R = D / B (heldout_share).
  const HeldoutShare share = heldout_share(fit, {});
  fit.explained = share.explained;
  fit.explained_ci = share.explained_ci;
  fit.z_score = share.z_score;
}

/// EffectFit::acts_on of each effect of `set`, from the weighted regressor J over `rows` (c channels per
/// row, one column per stacked parameter).
std::vector<std::vector<int>> acting_channels(const EffectSet& set, const Matrix& J, Eigen::Index c) {
  std::vector<std::vector<int>> out(set.effects.size());
  if (c == 0 || J.rows() % c != 0) return out;
  const Eigen::Index rows = J.rows() / c;
  for (std::size_t e = 0; e < set.effects.size(); ++e) {
    Vector energy = Vector::Zero(c);
    for (Eigen::Index k = 0; k < rows; ++k)
      for (Eigen::Index i = 0; i < c; ++i)
        energy(i) += J.row(k * c + i).segment(set.offset[e], set.length(e)).squaredNorm();
    const double largest = energy.allFinite() ? energy.maxCoeff() : 0.0;
    for (Eigen::Index i = 0; i < c && largest > 0.0; ++i)
      if (energy(i) > 1e-12 * largest) out[e].push_back(static_cast<int>(i));
  }
  return out;
}

/// The 95% interval at theta_hat (step 3): [low, high]. With instruments (Q, an orthonormal basis of
/// Z, instrumental_variables.hpp) the IV covariance s^2 (Q'J)^-1 (J'Q)^-1 and the jackknife of the
/// equations Q' r = 0; without (Q empty) Z = J, least squares.
std::pair<Vector, Vector> confidence_interval(const SetResidual& residual, const Vector& estimate, const FitContext& c,
                                              const std::vector<int>& rows, const Matrix& Q) {
  const Matrix J = residual.regressor(estimate, rows);
  const Vector r = residual.at(estimate, rows);
  const Matrix& Z = Q.size() > 0 ? Q : J;
  const auto p = J.cols();
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Matrix A = Z.transpose() * J;
  const Matrix A_inverse = A.fullPivLu().inverse();
  // An equation 0 = 0 (a row a criterion leaves out: zero residual, zero regressor) is no degree of freedom.
  Eigen::Index equations = 0;
  for (Eigen::Index i = 0; i < J.rows(); ++i) equations += r(i) != 0.0 || J.row(i).squaredNorm() > 0.0 ? 1 : 0;
  const double dof = std::max<double>(1.0, static_cast<double>(equations - p));
  Vector variance = (r.squaredNorm() / dof) * (A_inverse * (Z.transpose() * Z) * A_inverse.transpose()).diagonal();
  Vector quantile = Vector::Constant(p, 1.96);  // the Gauss-Newton variance's: normal
  // Delete-one-episode jackknife, each replicate one Gauss-Newton step from theta_hat.
  std::map<int, std::pair<Matrix, Vector>> per_episode;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int e = c.data->episode[static_cast<std::size_t>(rows[k])];
    auto [it, inserted] = per_episode.try_emplace(e, Matrix::Zero(p, p), Vector::Zero(p));
    const auto Zk = Z.middleRows(static_cast<Eigen::Index>(k) * n, n);
    it->second.first += Zk.transpose() * J.middleRows(static_cast<Eigen::Index>(k) * n, n);
    it->second.second += Zk.transpose() * r.segment(static_cast<Eigen::Index>(k) * n, n);
  }
  // An episode whose every equation a criterion leaves out (0 = 0) is no replicate.
  for (auto it = per_episode.begin(); it != per_episode.end();)
    it = it->second.first.isZero(0.0) && it->second.second.isZero(0.0) ? per_episode.erase(it) : std::next(it);
  const Vector g = Z.transpose() * r;
  const auto E = static_cast<double>(per_episode.size());
  if (E >= 2.0) {
    std::vector<Vector> replicates;
    Vector mean = Vector::Zero(p);
    for (const auto& [e, sums] : per_episode) {
      const Vector step = (A - sums.first).fullPivLu().solve(g - sums.second);
      if (!step.allFinite()) continue;
      replicates.push_back(estimate + step);
      mean += replicates.back();
    }
    if (replicates.size() >= 2) {
      mean /= static_cast<double>(replicates.size());
      Vector jack = Vector::Zero(p);
      for (const Vector& t : replicates) jack += (t - mean).cwiseAbs2();
      const auto R = static_cast<double>(replicates.size());
      jack *= (R - 1.0) / R;
      // Where the jackknife is the larger, its R replicates give it R - 1 degrees of freedom: the
      // quantile is Student's (student_t.hpp), 4.30 for R = 3, 2.45 for R = 7.
      const double t = batch_half_width(1.0, static_cast<int>(replicates.size()));
      for (Eigen::Index j = 0; j < p; ++j)
        quantile(j) = jack(j) > variance(j) ? t : quantile(j);
      variance = variance.cwiseMax(jack);
    }
  }
  // A covariance that is not finite (a regressor of zero at theta_hat: a fit that ran away to where
  // the data no longer see it) is no interval of zero width but an unbounded one.
  Vector half = quantile.cwiseProduct(variance.cwiseMax(0.0).cwiseSqrt());
  for (Eigen::Index j = 0; j < p; ++j)
    if (!std::isfinite(half(j)) || !(J.col(j).squaredNorm() > 0.0)) half(j) = std::numeric_limits<double>::infinity();
  return {estimate - half, estimate + half};
}

}  // namespace

DifferenceStep difference_step(const EffectParameter& spec, const Vector& theta, Eigen::Index j) {
  const double h = 1e-4 * std::max(std::abs(theta(j)), spec.scale);
  DifferenceStep d{theta, theta, 0.0};
  d.plus(j) = std::min(theta(j) + h, std::max(spec.highest(), theta(j)));
  d.minus(j) = std::max(theta(j) - h, std::min(spec.lowest(), theta(j)));
  d.width = d.plus(j) - d.minus(j);
  return d;
}

EffectFit led_by(EffectFit fit, const EffectValues& values) {
  fit.effect = values.effect;
  fit.parameters = values.parameters;
  fit.initial = fit.linear_estimate = values.initial;
  fit.estimate = values.estimate;
  fit.ci_low = values.ci_low;
  fit.ci_high = values.ci_high;
  fit.smoothing = values.smoothing;
  fit.null_value = values.null_value;
  fit.acts_on = values.acts_on;
  return fit;
}

EffectValues own_values(const EffectFit& fit) {
  return {fit.effect,   fit.parameters, fit.initial,    fit.estimate, fit.ci_low,
          fit.ci_high,  fit.smoothing,  fit.null_value, fit.acts_on};
}

HeldoutShare heldout_share(const EffectFit& fit, const std::vector<int>& channels) {
  HeldoutShare share;
  const Matrix& B = fit.heldout_channel_before;
  const Matrix& D = fit.heldout_channel_reduction;
  Vector b = Vector::Zero(B.rows()), d = Vector::Zero(B.rows());
  if (channels.empty()) {
    b = B.rowwise().sum();
    d = D.rowwise().sum();
  }
  for (int i : channels) {
    if (i < 0 || i >= B.cols()) throw std::invalid_argument("heldout_share: channel " + std::to_string(i) + " out of range");
    b += B.col(i);
    d += D.col(i);
  }
  std::tie(b, d) = batches_with_equations(b, d);
  const double before = b.sum();
  if (!(before > 0.0)) return share;
  share.explained = d.sum() / before;
  const auto K = static_cast<double>(b.size());
  if (K < 2.0) return share;
  const double se = std::sqrt(K / (K - 1.0) * (d - share.explained * b).squaredNorm()) / before;
  // K batches: Student's t with K - 1 degrees of freedom, z its normal equivalent (student_t.hpp).
  const int batches = static_cast<int>(b.size());
  share.explained_ci = batch_half_width(se, batches);
  share.z_score = se > 0.0 ? normal_equivalent(share.explained / se, batches) : (share.explained > 0.0 ? 1e6 : 0.0);
  return share;
}

std::pair<Vector, Vector> batches_with_equations(const Vector& before, const Vector& reduction) {
  std::vector<Eigen::Index> kept;
  for (Eigen::Index k = 0; k < before.size(); ++k)
    if (before(k) > 0.0 || reduction(k) != 0.0) kept.push_back(k);
  return {before(kept), reduction(kept)};
}

namespace {

EffectFit finish_fit(const EffectSet& set, const Vector& initial, const Vector& null, const Vector& theta_ls,
                     const Vector& theta_hat, const Vector& ci_low, const Vector& ci_high,
                     const std::vector<std::vector<int>>& acts_on, EffectFit fit);

/// S(theta), or +inf where the model diverges or does not accept theta (a mass of 0, say). With
/// instruments (Q not empty, instrumental_variables.hpp) the IV objective |Q' r(theta)|^2.
double objective_at(const SetResidual& residual, const VectorCRef& theta, const std::vector<int>& rows,
                    const Matrix& Q = {}) {
  try {
    bool finite = true;
    const Vector r = residual.at(theta, rows, &finite);
    if (!finite) return std::numeric_limits<double>::infinity();
    return Q.size() > 0 ? (Q.transpose() * r).squaredNorm() : r.squaredNorm();
  } catch (const std::invalid_argument&) {
    return std::numeric_limits<double>::infinity();
  }
}

/// The Gauss-Newton step d minimising |r - J d|^2, or with instruments |Q' (r - J d)|^2, which for
/// as many instruments as parameters solves Z' (r - J d) = 0.
Vector least_squares_step(const Matrix& J, const Vector& r, const Matrix& Q) {
  if (Q.size() == 0) return J.colPivHouseholderQr().solve(r);
  return (Q.transpose() * J).colPivHouseholderQr().solve(Q.transpose() * r);
}

/// Q, the instruments' basis of a set of effects at theta on `rows` (instrumental_variables.hpp): their
/// regressor evaluated at the simulated states. Empty without instruments.
Matrix instruments_of(const EffectSet& set, const Vector& theta, const FitContext& c, const std::vector<int>& rows) {
  const InverseDynamicsCriterion* criterion = c.criterion->inverse_dynamics();
  if (criterion == nullptr || criterion->instruments() == nullptr) return {};
  const FitContext at_simulation = instrument_context(c);
  const SetResidual residual(set, theta, at_simulation);
  return instrument_basis(residual.regressor(theta, rows), *criterion->instruments(), rows);
}

/// Gauss-Newton from `theta` (updated in place), at most `iterations` steps, each clamped to the
/// physical range and halved (up to 6 times) until S falls; stops when a step lowers S by less than
/// 1e-9 of it. Returns S at the final theta; `evaluations` counts the residual evaluations. With
/// instruments (Q not empty) the same on the projected residual Q' r and regressor Q' J: the steps of
/// the IV equations Z' r(theta) = 0 (instrumental_variables.hpp).
double refine_gauss_newton(const SetResidual& residual, Vector& theta, const Vector& lower, const Vector& upper,
                           const std::vector<int>& rows, int iterations, int& evaluations, const Matrix& Q = {}) {
  double at_theta = objective_at(residual, theta, rows, Q);
  ++evaluations;
  for (int k = 0; k < iterations && std::isfinite(at_theta); ++k) {
    const Vector r = residual.at(theta, rows);
    const Matrix J = residual.regressor(theta, rows);
    evaluations += 1 + 2 * static_cast<int>(theta.size());
    if (!J.allFinite() || !r.allFinite()) break;
    const Vector step = least_squares_step(J, r, Q);
    if (!step.allFinite()) break;
    bool lowered = false;
    for (double scale = 1.0; scale > 1.0 / 64.0 && !lowered; scale *= 0.5) {
      const Vector next = clamp_to(theta + scale * step, lower, upper);
      const double at_next = objective_at(residual, next, rows, Q);
      ++evaluations;
      if (at_next < at_theta) {
        const bool converged = at_theta - at_next <= 1e-9 * at_theta;
        theta = next;
        at_theta = at_next;
        lowered = true;
        if (converged) return at_theta;
      }
    }
    if (!lowered) break;
  }
  return at_theta;
}

/// Gauss-Newton steps from theta_0: effects linear in their parameters need two on one step or the
/// force residual (the least-squares step, then what the integrator leaves of the nonlinearity); the
/// others (a mass, a length, a delay), and every effect under the simulation criterion, whose
/// prediction over a window is not linear in any parameter, up to this many.
constexpr int kLinearRefinements = 2;
constexpr int kNonlinearRefinements = 12;

/// Each parameter's scale on the data (EffectFit::scale): max(|null_j|, |m| / |J_j|) over the
/// velocity rows of the weighted training rows, m = sqrt(w) (x_hat_{r+1} - x_r) the model's own
/// predicted change (x_hat = x_next - residual under the criterion). Infinite where J_j is zero on
/// them (nothing to compare with).
Vector data_scales(const Matrix& J, const FitContext& c, const std::vector<int>& rows, const Vector& null) {
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const std::vector<int> channels = c.criterion->scale_channels(c);
  double motion = 0.0;
  Vector column = Vector::Zero(J.cols());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int r = rows[k];
    for (int i : channels) {
      if (i >= n) continue;
      const double w = c.weights(i);
      const double change = c.criterion->own_change(c, r, i);
      motion += w * change * change;
      column += J.row(static_cast<Eigen::Index>(k) * n + i).transpose().cwiseAbs2();
    }
  }
  Vector scale(J.cols());
  for (Eigen::Index j = 0; j < J.cols(); ++j)
    scale(j) = std::max(std::abs(null(j)), column(j) > 0.0 ? std::sqrt(motion / column(j))
                                                           : std::numeric_limits<double>::infinity());
  return scale;
}

/// Test 1 of effect_test.hpp on a finished fit: a covariance that is not finite, a parameter whose
/// regressor is a finite difference of the model (not a linear force's basis) and whose typical size
/// (EffectParameter::scale) moves the predictions less than kRoundingLevel of the model's own motion (a
/// regressor of rounding: a centre of mass moved along the only axis its body turns about), a quantity
/// that must
/// stay positive (a mass: EffectParameter::strictly_positive) whose scale on the data exceeds kRunawayFactor times its
/// own value, or a parameter further than kRunawayFactor times its scale from its value without the
/// effect.
void check_identifiable(const EffectSet& set, const Vector& theta_hat, const Vector& ci_low, const Vector& ci_high,
                        const Vector& null, EffectFit& fit) {
  // The columns of forces linear in their parameters are their exact bases, never rounding.
  const std::vector<Eigen::Index> differences = set.columns(true).others;
  const auto from_differences = [&](Eigen::Index j) {
    return std::find(differences.begin(), differences.end(), j) != differences.end();
  };
  for (Eigen::Index j = 0; j < theta_hat.size() && fit.identifiable; ++j) {
    const EffectParameter& spec = set.parameter(j);
    if (!std::isfinite(ci_low(j)) || !std::isfinite(ci_high(j))) {
      fit.identifiable = false;
      fit.not_identifiable = fmt::format("the covariance of {} = {:.4g} {} is not finite: the data do not see it there",
                                         spec.name, theta_hat(j), spec.unit);
    } else if (from_differences(j) && fit.scale(j) * kRoundingLevel > spec.scale) {
      fit.identifiable = false;
      fit.not_identifiable = fmt::format(
          "it does not change the predictions beyond rounding: a change of {} by its typical size of {:.3g} {} moves "
          "them by {:.2g} of what the model itself moves them",
          spec.name, spec.scale, spec.unit, spec.scale / fit.scale(j));
    } else if (spec.strictly_positive && null(j) > 0.0 && fit.scale(j) > kRunawayFactor * null(j)) {
      fit.identifiable = false;
      fit.not_identifiable = fmt::format(
          "the data barely see {}: only a change of {:.3g} {}, {:.3g} times its value of {:.4g} {}, moves the predictions "
          "as much as the model itself moves them; more than {:g} times is a quantity these data cannot weigh",
          spec.name, fit.scale(j), spec.unit, fit.scale(j) / null(j), null(j), spec.unit, kRunawayFactor);
    } else if (std::abs(theta_hat(j) - null(j)) > kRunawayFactor * fit.scale(j)) {
      fit.identifiable = false;
      fit.not_identifiable =
          fmt::format("{} = {:.4g} {} lies {:.3g} times its scale on these data ({:.3g} {}) from its value without the "
                      "effect ({:.4g}); more than {:g} times is a fit that ran away",
                      spec.name, theta_hat(j), spec.unit, std::abs(theta_hat(j) - null(j)) / fit.scale(j), fit.scale(j),
                      spec.unit, null(j), kRunawayFactor);
    }
  }
}

/// Steps 1-4 on the stacked parameters of `set`, from `initial`; `probe` as in SetResidual.
EffectFit fit_set(const EffectSet& set, const Vector& initial, const FitContext& c, bool probe = true) {
  if (c.data == nullptr) throw std::invalid_argument("fit_effect: no data");
  const auto p = set.size();
  const std::vector<int> training = c.data->rows(false);
  Vector lower(p), upper(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    lower(j) = set.parameter(j).lowest();
    upper(j) = set.parameter(j).highest();
  }
  Vector theta_ls = initial, theta_hat = initial, ci_low = initial, ci_high = initial;
  EffectFit fit;
  fit.training_objective_before = weighted_model_residual(c, training).squaredNorm();
  const Vector null = set.null_values(c.model);

  // 1. Linear least squares at theta_0 (a Gauss-Newton step from a warm start for a joint fit).
  const SetResidual residual(set, initial, c, probe);
  const Matrix J = residual.regressor(initial, training);
  fit.regressor = J.col(0);
  fit.scale = data_scales(J, c, training, null);
  const std::vector<std::vector<int>> acts_on = acting_channels(set, J, c.weights.size());
  // IDIM-IV: the instruments of the set, fixed at theta_0 (instrumental_variables.hpp).
  const Matrix Q = J.allFinite() ? instruments_of(set, initial, c, training) : Matrix();
  if (!(J.col(0).norm() > 0.0) || !J.allFinite()) {
    fit.identifiable = false;
    fit.not_identifiable = "it does not change the predictions";
    fit.training_objective_after = residual.at(initial, training).squaredNorm();
  } else if (c.criterion->inverse_dynamics() && c.criterion->inverse_dynamics()->instruments() && Q.size() == 0) {
    fit.identifiable = false;
    fit.not_identifiable = "it has no instrument: its regressor at the simulated states is zero or collinear";
    fit.training_objective_after = residual.at(initial, training).squaredNorm();
  } else {
    const Vector r_initial = residual.at(initial, training);
    const Vector delta = least_squares_step(J, r_initial, Q);
    theta_ls = clamp_to(initial + delta, lower, upper);
    // 2. Gauss-Newton on S(theta) inside the physical range, from theta_0: its first step is the
    // least-squares step above, halved when it does not lower S (a nonlinear effect far from theta_0).
    theta_hat = initial;
    fit.training_objective_after =
        refine_gauss_newton(residual, theta_hat, lower, upper, training,
                            set.linear() && c.criterion->window() == 1 ? kLinearRefinements : kNonlinearRefinements,
                            fit.evaluations, Q);
    // The IV fit minimised the projected objective; the fit's objective is the residual's own.
    if (Q.size() > 0) fit.training_objective_after = objective_at(residual, theta_hat, training);

    // 3. Interval, and whether the data determine the fit.
    std::tie(ci_low, ci_high) = confidence_interval(residual, theta_hat, c, training, Q);
    check_identifiable(set, theta_hat, ci_low, ci_high, null, fit);
  }
  // A closed form that stood on probes of the model must hold at the estimate too; where it does not,
  // the fit is the rebuilt model's.
  if (residual.probed() && !residual.matches_at(theta_hat)) return fit_set(set, initial, c, false);
  // 4. Held-out scores; then each effect's slice.
  score_heldout(residual, theta_hat, c, fit);
  return finish_fit(set, initial, null, theta_ls, theta_hat, ci_low, ci_high, acts_on, std::move(fit));
}

/// Each effect's slice of the stacked estimates into `fit` (the candidate) and fit.refitted (the others).
EffectFit finish_fit(const EffectSet& set, const Vector& initial, const Vector& null, const Vector& theta_ls,
                     const Vector& theta_hat, const Vector& ci_low, const Vector& ci_high,
                     const std::vector<std::vector<int>>& acts_on, EffectFit fit) {
  const Vector scale = fit.scale;
  for (std::size_t e = 0; e < set.effects.size(); ++e) {
    const Eigen::Index at = set.offset[e], length = set.length(e);
    const auto& smoothing = set.effects[e]->smoothing;
    EffectValues values{set.effects[e]->name,          set.effects[e]->parameters,   initial.segment(at, length),
                        theta_hat.segment(at, length), ci_low.segment(at, length), ci_high.segment(at, length),
                        smoothing ? smoothing->width : 0.0,                          null.segment(at, length),
                        acts_on[e]};
    if (e == 0) {
      fit.effect = values.effect;
      fit.parameters = values.parameters;
      fit.initial = values.initial;
      fit.linear_estimate = theta_ls.segment(at, length);
      fit.estimate = values.estimate;
      fit.ci_low = values.ci_low;
      fit.ci_high = values.ci_high;
      fit.smoothing = values.smoothing;
      fit.null_value = values.null_value;
      fit.acts_on = values.acts_on;
      if (scale.size() == theta_hat.size()) fit.scale = scale.segment(at, length);
    } else {
      fit.refitted.push_back(std::move(values));
    }
  }
  return fit;
}

}  // namespace

EffectFit fit_effect(const LibraryEffect& effect, const FitContext& c) { return fit_jointly(effect, {}, c); }

EffectFit fit_jointly(const LibraryEffect& effect, const std::vector<RefitEffect>& refit, const FitContext& c,
                      const Vector& start) {
  EffectSet set;
  set.add(effect);
  for (const RefitEffect& r : refit) {
    if (r.effect == nullptr) throw std::invalid_argument("fit_jointly: a refitted effect is null");
    for (const LibraryEffect* e : set.effects)
      if (e->name == r.effect->name) throw std::invalid_argument("fit_jointly: effect '" + e->name + "' appears twice");
    if (r.start.size() != static_cast<Eigen::Index>(r.effect->parameters.size()))
      throw std::invalid_argument("fit_jointly: the start of '" + r.effect->name + "' has the wrong size");
    set.add(*r.effect);
  }
  Vector initial(set.size());
  initial.head(set.length(0)) = start.size() > 0 ? start : c.model.current_values(effect);
  // A delay is not found by a Gauss-Newton step from 0 (its regressor there is a difference of
  // inputs): it starts at the lag of the peak cross-correlation (delay_start.hpp).
  if (start.size() == 0 && effect.kind == EffectKind::InputDelay && c.model.input_delay == 0.0)
    initial(0) = input_delay_start(c);
  for (std::size_t e = 1; e < set.effects.size(); ++e) initial.segment(set.offset[e], set.length(e)) = refit[e - 1].start;
  return fit_set(set, initial, c);
}

EffectFit score_effect(const LibraryEffect& effect, const VectorCRef& values, const FitContext& c) {
  if (c.data == nullptr) throw std::invalid_argument("score_effect: no data");
  static_cast<void>(c.model.with(effect, values));  // validates the values
  EffectFit fit;
  fit.effect = effect.name;
  fit.parameters = effect.parameters;
  fit.initial = fit.null_value = c.model.current_values(effect);
  fit.linear_estimate = fit.estimate = fit.ci_low = fit.ci_high = values;
  if (effect.smoothing) fit.smoothing = effect.smoothing->width;
  const std::vector<int> training = c.data->rows(false);
  EffectSet set;
  set.add(effect);
  fit.training_objective_before = weighted_model_residual(c, training).squaredNorm();
  const SetResidual residual(set, values, c, false);
  fit.training_objective_after = residual.at(values, training).squaredNorm();
  fit.acts_on = acting_channels(set, residual.regressor(values, training), c.weights.size()).front();
  score_heldout(residual, values, c, fit);
  return fit;
}

namespace {

/// True when the system's entry declares `a` and `b` the same physics (system_registry.hpp).
bool same_physics(const SystemEntry& entry, const std::string& a, const std::string& b) {
  for (const auto& group : entry.same_physics)
    if (std::find(group.begin(), group.end(), a) != group.end() && std::find(group.begin(), group.end(), b) != group.end())
      return true;
  return false;
}

}  // namespace

std::vector<RankedEffect> rank_effects(const FitContext& context, double alias_gain,
                                       const std::function<void(const std::string&)>& progress,
                                       const std::vector<RefitEffect>& refit, int threads) {
  const SystemEntryPtr system = find_system(context.model.system);
  // Candidates: the library without the effects being refitted and their declared aliases.
  std::vector<const LibraryEffect*> candidates;
  const std::vector<LibraryEffect> library = candidate_effects(context.model);
  for (const LibraryEffect& effect : library) {
    if (std::find(context.excluded.begin(), context.excluded.end(), effect.name) != context.excluded.end()) continue;
    bool chosen = false;
    for (const RefitEffect& r : refit)
      chosen = chosen || r.effect->name == effect.name || same_physics(*system, r.effect->name, effect.name);
    if (!chosen) candidates.push_back(&effect);
  }
  std::vector<EffectFit> fits(candidates.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex report;
  // Each line says how long the candidates took so far and, at that pace, how long the others will take
  // (on a long record each fit goes over every sample, so the pace holds).
  const auto start = std::chrono::steady_clock::now();
  ForkJoin workers;
  workers.run(std::max(1, std::min<int>(threads, static_cast<int>(candidates.size()))), [&](int, int) {
    for (std::size_t i = next++; i < candidates.size(); i = next++) {
      fits[i] = fit_jointly(*candidates[i], refit, context);
      if (progress) {
        const std::lock_guard<std::mutex> lock(report);
        const std::size_t finished = ++done, left = candidates.size() - finished;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress(fmt::format("effect {}/{} fitted: {} explains {:.1f}% ({:.1f} s so far{})", finished,
                             candidates.size(), fits[i].effect, 100.0 * fits[i].explained, seconds,
                             left == 0 ? std::string()
                                       : fmt::format(", about {:.0f} s for the other {}",
                                                     seconds / static_cast<double>(finished) * static_cast<double>(left),
                                                     left)));
      }
    }
  });
  // The order of standing (effect_test.hpp): identifiable fits whose interval excludes their value
  // without them, then those whose interval holds it, each by screening score (below); the fits that
  // are not identifiable last, unranked.
  const auto standing = [](const EffectFit& f) { return !f.identifiable ? 2 : interval_contains_null(own_values(f)) ? 1 : 0; };
  // Aliases: the joint fit of the pair does no better than either alone, or the same physics by
  // declaration. An effect that explains nothing alone is nobody's alias.
  const LinearisedFits joint(context, fits, refit, threads);
  const auto aliases = [&](int i, int j) {
    if (joint.gain({j}, {}) < alias_gain) return false;
    if (same_physics(*system, fits[static_cast<std::size_t>(i)].effect, fits[static_cast<std::size_t>(j)].effect))
      return true;
    return joint.gain({i, j}, {i}) < alias_gain && joint.gain({i, j}, {j}) < alias_gain;
  };
  // Within a standing, the order is the cross-validated screening score on the training rows
  // (linearised_fits.hpp): the held-out rows score the first entry and its rivals, so they must not
  // also choose it among all candidates (the best of many held-out scores is biased upwards).
  std::vector<double> screening(fits.size());
  for (std::size_t i = 0; i < fits.size(); ++i) screening[i] = joint.screening_left({static_cast<int>(i)});
  std::vector<std::size_t> order(fits.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const int sa = standing(fits[a]), sb = standing(fits[b]);
    return sa != sb ? sa < sb : (sa < 2 && screening[a] < screening[b]);
  });
  std::vector<bool> used(fits.size(), false);
  std::vector<RankedEffect> out;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    if (used[i]) continue;
    used[i] = true;
    RankedEffect entry{fits[i], {}};
    for (std::size_t l = k + 1; l < order.size() && fits[i].identifiable; ++l) {
      const std::size_t j = order[l];
      if (used[j] || !fits[j].identifiable) continue;
      if (!aliases(static_cast<int>(i), static_cast<int>(j))) continue;
      used[j] = true;
      entry.aliases.push_back(fits[j]);
    }
    out.push_back(std::move(entry));
  }
  // Rivals: ranked entries that the held-out rows do not tell from the first, batch by batch.
  for (std::size_t k = 1; k < out.size() && standing(out.front().fit) == 0; ++k) {
    if (standing(out[k].fit) != 0) break;
    const HeldoutComparison c = compare_heldout(out[k].fit, out.front().fit);
    if (!c.comparable) continue;
    out[k].behind_first = c.difference;
    out[k].behind_first_ci = c.difference_ci;
    out[k].rival = c.difference + c.difference_ci >= 0.0;
  }
  return out;
}

}  // namespace gpilqg::diagnosis
