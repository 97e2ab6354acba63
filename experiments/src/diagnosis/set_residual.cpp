#include "set_residual.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <utility>

#include "gpilqg/core/fork_join.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"

namespace gpilqg::diagnosis {

void EffectSet::add(const LibraryEffect& effect) {
  effects.push_back(&effect);
  offset.push_back(offset.back() + static_cast<Eigen::Index>(effect.parameters.size()));
}

bool EffectSet::linear() const {
  return std::all_of(effects.begin(), effects.end(), [](const LibraryEffect* e) { return e->linear; });
}

const EffectParameter& EffectSet::parameter(Eigen::Index j) const {
  std::size_t e = 0;
  while (offset[e + 1] <= j) ++e;
  return effects[e]->parameters[static_cast<std::size_t>(j - offset[e])];
}

Vector EffectSet::null_values(const ModelSpec& base) const {
  Vector out(size());
  for (std::size_t e = 0; e < effects.size(); ++e) out.segment(offset[e], length(e)) = base.current_values(*effects[e]);
  return out;
}

ModelSpec EffectSet::model_at(const ModelSpec& base, const VectorCRef& theta) const {
  // A value past its bound by a difference step's size (1e-4 of the value, added at the bound) is
  // taken at the bound: the fit's own rounding, not a value for ModelSpec::with to refuse (which the
  // command would report as bad data).
  Vector at = theta;
  for (Eigen::Index j = 0; j < at.size(); ++j) {
    const EffectParameter& p = parameter(j);
    const double lo = p.lowest(), hi = p.highest();
    if (at(j) > hi && std::isfinite(hi) && at(j) <= hi + 1e-3 * std::max(std::abs(hi), p.scale)) at(j) = hi;
    if (at(j) < lo && std::isfinite(lo) && at(j) >= lo - 1e-3 * std::max(std::abs(lo), p.scale)) at(j) = lo;
  }
  ModelSpec model = base;
  for (std::size_t e = 0; e < effects.size(); ++e) model = model.with(*effects[e], at.segment(offset[e], length(e)));
  return model;
}

EffectSet::Columns EffectSet::columns(bool with_forces) const {
  Columns out;
  for (std::size_t e = 0; e < effects.size(); ++e) {
    const bool force = with_forces && linear_forces({effects[e]});
    if (force) out.forces.push_back(effects[e]);
    for (Eigen::Index j = offset[e]; j < offset[e + 1]; ++j) (force ? out.force_columns : out.others).push_back(j);
  }
  return out;
}

namespace {

/// True when `actual` and `predicted`, residuals at some theta, agree to rounding: their difference
/// is below kAffineTolerance of the larger of the change from `base` (the residual at theta0) and
/// `base` itself, in the Euclidean norm.
bool affine_to_rounding(const Vector& actual, const Vector& predicted, const Vector& base) {
  constexpr double kAffineTolerance = 1e-9;
  const double size = std::max((actual - base).norm(), base.norm());
  return actual.allFinite() && (actual - predicted).norm() <= kAffineTolerance * size;
}

}  // namespace

SetResidual::SetResidual(const EffectSet& set, const Vector& theta0, const FitContext& c, bool probe)
    : set_(set), c_(c) {
  if (!c.criterion->inverse_dynamics()) return;
  if (linear_forces(set.effects)) {
    affine_.emplace(set.model_at(c.model, theta0), set.effects, theta0, c);
  } else if (probe && c.probe_affine) {
    affine_ = probed_affine_residual(theta0);
    probed_ = affine_.has_value();
  }
}

bool SetResidual::matches_at(const VectorCRef& theta) const {
  if (!probed_) return true;
  const std::vector<int> rows = all_rows(*c_.data);
  try {
    return affine_to_rounding(c_.criterion->weighted_residual(set_.model_at(c_.model, theta), c_, rows),
                              affine_->weighted(theta, rows), affine_->weighted(theta0_, rows));
  } catch (const std::invalid_argument&) {
    return false;
  }
}

Vector SetResidual::at(const VectorCRef& theta, const std::vector<int>& rows, bool* finite) const {
  if (affine_) return affine_->weighted(theta, rows);
  for (const Evaluation& e : residuals_)
    if (e.theta == theta && e.rows == rows) {
      if (finite != nullptr && !e.finite) *finite = false;
      return e.value;
    }
  const ModelSpec spec = set_.model_at(c_.model, theta);
  Evaluation e{theta, rows, {}, true};
  e.value = c_.criterion->weighted_residual(spec, c_, rows, &e.finite);
  if (finite != nullptr && !e.finite) *finite = false;
  return remember(residuals_, std::move(e)).value;
}

Matrix SetResidual::regressor(const VectorCRef& theta, const std::vector<int>& rows) const {
  if (affine_) return affine_->weighted_regressor(rows);
  for (const Evaluation& e : regressors_)
    if (e.theta == theta && e.rows == rows) return e.value;
  Matrix J(static_cast<Eigen::Index>(rows.size()) * c_.weights.size(), theta.size());
  const EffectSet::Columns columns = set_.columns(c_.criterion->inverse_dynamics() != nullptr);
  std::vector<Vector> points;  // theta - h e_j, theta + h e_j of every other column j
  std::vector<double> inverse_widths;
  for (Eigen::Index j : columns.others) {
    const DifferenceStep d = difference_step(set_.parameter(j), theta, j);
    points.push_back(d.minus);
    points.push_back(d.plus);
    inverse_widths.push_back(d.inverse_width());
  }
  const std::vector<Vector> r = rebuilt(points, rows);
  // The residual is x' - phi, so d phi / d theta = -(d residual / d theta).
  for (std::size_t i = 0; i < columns.others.size(); ++i)
    J.col(columns.others[i]) = (r[2 * i] - r[2 * i + 1]) * inverse_widths[i];
  if (!columns.forces.empty())
    J(Eigen::all, columns.force_columns) =
        weighted_force_regressor(set_.model_at(c_.model, theta), columns.forces, c_, rows);
  return remember(regressors_, Evaluation{theta, rows, std::move(J), true}).value;
}

std::vector<Vector> SetResidual::rebuilt(const std::vector<Vector>& thetas, const std::vector<int>& rows) const {
  std::vector<Vector> out(thetas.size());
  std::atomic<std::size_t> next{0};
  ForkJoin workers;
  workers.run(std::max(1, std::min<int>(c_.threads, static_cast<int>(thetas.size()))), [&](int, int) {
    for (std::size_t i = next++; i < thetas.size(); i = next++)
      out[i] = c_.criterion->weighted_residual(set_.model_at(c_.model, thetas[i]), c_, rows);
  });
  return out;
}

const SetResidual::Evaluation& SetResidual::remember(std::deque<Evaluation>& kept, Evaluation e) {
  constexpr std::size_t kKept = 4;
  if (kept.size() == kKept) kept.pop_back();
  kept.push_front(std::move(e));
  return kept.front();
}

std::optional<AffineForceResidual> SetResidual::probed_affine_residual(const Vector& theta0) {
  theta0_ = theta0;
  const std::vector<int> rows = all_rows(*c_.data);
  const auto p = theta0.size();
  Vector step(p);
  for (Eigen::Index j = 0; j < p; ++j) step(j) = set_.parameter(j).scale;
  if (!step.allFinite() || !(step.minCoeff() > 0.0)) return std::nullopt;
  try {
    // theta0, each parameter that is not a linear force's moved by its scale, and every parameter
    // moved by two scales: one batch of independent evaluations.
    const EffectSet::Columns columns = set_.columns(true);
    std::vector<Vector> points{theta0};
    for (Eigen::Index j : columns.others) {
      points.push_back(theta0);
      points.back()(j) += step(j);
    }
    const Vector far = theta0 + 2.0 * step;
    points.push_back(far);
    const std::vector<Vector> r = rebuilt(points, rows);
    const Vector& r0 = r.front();
    Matrix G(r0.size(), p);
    for (std::size_t i = 0; i < columns.others.size(); ++i)
      G.col(columns.others[i]) = (r0 - r[i + 1]) / step(columns.others[i]);
    if (!columns.forces.empty())
      G(Eigen::all, columns.force_columns) =
          weighted_force_regressor(set_.model_at(c_.model, theta0), columns.forces, c_, rows);
    if (!affine_to_rounding(r.back(), r0 - G * (far - theta0), r0)) return std::nullopt;
    return AffineForceResidual(theta0, c_.weights.size(), r0, std::move(G));
  } catch (const std::invalid_argument&) {  // a probe outside the physical range, or a singular model
    return std::nullopt;
  }
}

}  // namespace gpilqg::diagnosis
