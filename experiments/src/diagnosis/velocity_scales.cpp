#include "gpilqg/experiments/diagnosis/velocity_scales.hpp"

#include "gpilqg/experiments/diagnosis/affine_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace gpilqg::diagnosis {

double training_rms(const Transitions& data, int velocity) {
  double sum = 0.0;
  long count = 0;
  for (int r : data.rows(false)) {
    const double v = data.x(r, velocity);
    sum += v * v;
    ++count;
  }
  return count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
}

LibraryEffect viscous_twin(const LibraryEffect& coulomb, double rms) {
  LibraryEffect out = with_smoothing(coulomb, kViscousWidth * rms);
  out.name += " (viscous)";
  out.smoothing.reset();
  return out;
}

namespace {

/// The column a Coulomb effect at smoothing `v0` adds to the weighted residual on `rows`: under inverse
/// dynamics the force's own regressor (the residual is affine in the force's level there, so no model
/// is evaluated), else the secant of the residual r0 over one parameter scale.
Vector coulomb_column(const FitContext& c, const LibraryEffect& coulomb, double v0, const Vector& r0,
                      const std::vector<int>& rows) {
  const LibraryEffect effect = with_smoothing(coulomb, v0);
  if (c.criterion->inverse_dynamics() && linear_forces({&effect})) return weighted_force_regressor(c.model, {&effect}, c, rows).col(0);
  const double h = effect.parameters[0].scale;
  return (r0 - weighted_residual_of(c.model.with(effect, Vector::Constant(1, h)), c, rows)) / h;
}

/// min over (tau, b) of S for `effect` at smoothing `v0` added to the model beside a viscous friction
/// of its coordinate, linear least squares on the two columns: J(v0) and the viscous column `viscous`
/// (file comment). Without the viscous column the switch's width would also stand for the slope at
/// speed: a Coulomb friction fitted alone where both act takes the widest v0 of the grid, a saturating
/// viscous friction, and keeps it in every set it screens in.
double profiled_objective(const FitContext& c, const LibraryEffect& coulomb, double v0, const Vector& r0,
                          const Vector& viscous, const std::vector<int>& rows) {
  Matrix J(r0.size(), 2);
  J.col(0) = coulomb_column(c, coulomb, v0, r0, rows);
  J.col(1) = viscous;
  if (!J.allFinite() || !(J.col(0).squaredNorm() > 0.0)) return r0.squaredNorm();
  // Least squares by a rank-revealing QR: a viscous column of zeros (a coordinate at rest) drops out.
  const Eigen::ColPivHouseholderQR<Matrix> qr(J);
  const Vector theta = qr.solve(r0);
  return (r0 - J * theta).squaredNorm();
}

/// The v0 = f s minimising `objective(v0)` over the grid f of kSmoothingGrid, refined by the vertex of
/// the parabola through the best grid point and its neighbours in log v0; `fallback` when s is 0.
template <class Objective>
double minimising_smoothing(double rms, double fallback, Objective&& objective) {
  if (!(rms > 0.0) || !std::isfinite(rms)) return fallback;
  const auto points = static_cast<int>(std::size(kSmoothingGrid));
  std::vector<double> values(static_cast<std::size_t>(points));
  int best = 0;
  for (int i = 0; i < points; ++i) {
    values[static_cast<std::size_t>(i)] = objective(kSmoothingGrid[i] * rms);
    if (values[static_cast<std::size_t>(i)] < values[static_cast<std::size_t>(best)]) best = i;
  }
  const double v0 = kSmoothingGrid[best] * rms;
  if (best == 0 || best == points - 1) return v0;
  const double x0 = std::log(kSmoothingGrid[best - 1]), x1 = std::log(kSmoothingGrid[best]),
               x2 = std::log(kSmoothingGrid[best + 1]);
  const double y0 = values[static_cast<std::size_t>(best - 1)], y1 = values[static_cast<std::size_t>(best)],
               y2 = values[static_cast<std::size_t>(best + 1)];
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1), curvature = (d12 - d01) / (x2 - x0);
  if (!(curvature > 0.0)) return v0;
  // p(x) = y0 + d01 (x - x0) + curvature (x - x0)(x - x1), p'(x) = 0 at:
  const double x = std::clamp(0.5 * (x0 + x1) - d01 / (2.0 * curvature), x0, x2);
  const double candidate = std::exp(x) * rms;
  return objective(candidate) < y1 ? candidate : v0;
}

}  // namespace

ModelSpec with_fitted_smoothing(const FitContext& c) {
  ModelSpec out = c.model;
  const std::vector<int> rows = c.data->rows(false);
  Vector r0;
  for (const LibraryEffect& effect : candidate_effects(c.model)) {
    if (!effect.smoothing || c.model.smoothing.count(effect.name) > 0) continue;
    const bool present = std::any_of(c.model.forces.begin(), c.model.forces.end(),
                                     [&](const auto& force) { return force.first == effect.name; });
    if (present) continue;
    if (r0.size() == 0) r0 = weighted_residual_of(c.model, c, rows);
    const double rms = training_rms(*c.data, effect.smoothing->velocity);
    // The viscous friction of the coordinate: the same effect at kViscousWidth times the rms speed.
    const Vector viscous = rms > 0.0 ? coulomb_column(c, effect, kViscousWidth * rms, r0, rows) : Vector::Zero(r0.size());
    out.smoothing[effect.name] = minimising_smoothing(
        rms, effect.smoothing->width, [&](double v0) { return profiled_objective(c, effect, v0, r0, viscous, rows); });
  }
  return out;
}

}  // namespace gpilqg::diagnosis

namespace gpilqg::diagnosis {

std::map<std::string, double> joint_smoothing(const FitContext& c, const EffectFit& fit) {
  const std::vector<EffectFit> members = member_fits(fit);
  std::vector<int> all(members.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  // Beside every Coulomb member, a viscous friction of its coordinate, as when it was fitted alone
  // (with_fitted_smoothing): refitted with the set, never a member of it. Without it, in a set that
  // lacks the coordinate's viscous friction the width would stand for the slope at speed again and
  // take the top of the grid. Where the set has that viscous friction, the two columns are one and
  // the fit is the same.
  std::vector<LibraryEffect> viscous;
  viscous.reserve(members.size());
  for (const EffectFit& member : members) {
    const LibraryEffect effect = find_candidate(c.model, member.effect);
    const double rms = effect.smoothing ? training_rms(*c.data, effect.smoothing->velocity) : 0.0;
    if (rms > 0.0) viscous.push_back(viscous_twin(effect, rms));
  }
  std::vector<RefitEffect> beside;
  for (const LibraryEffect& v : viscous) beside.push_back({&v, Vector::Zero(1)});
  FitContext trial = c;
  std::map<std::string, double> out;
  // The set linearised once; a grid value replaces only the Coulomb member's own columns (its
  // smoothing moves nothing else), unless the member is a force of the model itself, whose residual
  // its smoothing then changes too.
  LinearisedFits fits(trial, members, beside, c.threads, true);
  for (std::size_t m = 0; m < members.size(); ++m) {
    const LibraryEffect effect = find_candidate(c.model, members[m].effect);
    if (!effect.smoothing) continue;
    const bool in_model = std::any_of(c.model.forces.begin(), c.model.forces.end(),
                                      [&](const auto& force) { return force.first == effect.name; });
    const auto objective = [&](double width) {
      trial.model.smoothing[effect.name] = width;
      if (in_model) return LinearisedFits(trial, members, beside, c.threads).training_left(all);
      fits.relinearise(static_cast<int>(m), trial);
      return fits.training_left(all);
    };
    const double v0 = minimising_smoothing(training_rms(*c.data, effect.smoothing->velocity), effect.smoothing->width,
                                           objective);
    trial.model.smoothing[effect.name] = v0;
    if (in_model)
      fits = LinearisedFits(trial, members, beside, c.threads, true);
    else
      fits.relinearise(static_cast<int>(m), trial);
    out[effect.name] = v0;
  }
  return out;
}

}  // namespace gpilqg::diagnosis
