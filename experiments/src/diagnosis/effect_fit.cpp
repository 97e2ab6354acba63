#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <stdexcept>

#include <Eigen/Dense>
#include <nlopt.hpp>

#include "gpilqg/core/system_registry.hpp"

namespace gpilqg::diagnosis {

std::shared_ptr<const StepModel> make_step_model(const ModelSpec& model, Integrator integrator, double dt, int substeps) {
  return gpilqg::make_step_model(model.build(), integrator, dt, substeps);
}

namespace {

/// sqrt(w_i) (x_{t+1,i} - phi_i(x_t, u_t)) stacked row by row over `rows` (index r * n + i); `finite`
/// turns false when a prediction diverged (prediction_diverged: not finite or beyond 1e12). Such a
/// prediction is replaced by x_t, as in one_step_predictions, so every entry stays finite and its
/// square cannot overflow.
Vector weighted_residual(const StepModel& model, const FitContext& c, const std::vector<int>& rows, bool* finite) {
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Vector sqrt_w = c.weights.cwiseSqrt();
  Vector out(static_cast<Eigen::Index>(rows.size()) * n);
  Vector next(n);
  const auto workspace = model.make_workspace();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int r = rows[k];
    model.step(c.data->x.row(r).transpose(), c.data->u.row(r).transpose(), next, nullptr, *workspace);
    if (prediction_diverged(next)) {
      if (finite != nullptr) *finite = false;
      next = c.data->x.row(r).transpose();
    }
    out.segment(static_cast<Eigen::Index>(k) * n, n) = sqrt_w.cwiseProduct(c.data->x_next.row(r).transpose() - next);
  }
  return out;
}

Vector weighted_residual_at(const LibraryEffect& effect, const VectorCRef& theta, const FitContext& c,
                            const std::vector<int>& rows, bool* finite = nullptr) {
  const auto model = make_step_model(c.model.with(effect, theta), c.integrator, c.dt, c.substeps);
  return weighted_residual(*model, c, rows, finite);
}

/// Weighted regressor d phi / d theta (rows.size() n x p) by central differences (one-sided when the
/// lower step would leave the physical range).
Matrix regressor(const LibraryEffect& effect, const VectorCRef& theta, const FitContext& c, const std::vector<int>& rows) {
  const auto p = theta.size();
  Matrix J(static_cast<Eigen::Index>(rows.size()) * c.weights.size(), p);
  for (Eigen::Index j = 0; j < p; ++j) {
    const EffectParameter& spec = effect.parameters[static_cast<std::size_t>(j)];
    const double h = 1e-4 * std::max(std::abs(theta(j)), spec.scale);
    Vector plus = theta, minus = theta;
    plus(j) += h;
    minus(j) -= h;
    double width = 2.0 * h;
    if (minus(j) < spec.lower) {
      minus(j) = theta(j);
      width = h;
    }
    // The residual is x' - phi, so d phi / d theta = -(d residual / d theta).
    J.col(j) = (weighted_residual_at(effect, minus, c, rows) - weighted_residual_at(effect, plus, c, rows)) / width;
  }
  return J;
}

Vector weighted_model_residual(const FitContext& c, const std::vector<int>& rows) {
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Vector sqrt_w = c.weights.cwiseSqrt();
  Vector out(static_cast<Eigen::Index>(rows.size()) * n);
  for (std::size_t k = 0; k < rows.size(); ++k)
    out.segment(static_cast<Eigen::Index>(k) * n, n) = sqrt_w.cwiseProduct(c.residual.row(rows[k]).transpose());
  return out;
}

Vector clamp_to(const Vector& theta, const Vector& lo, const Vector& hi) { return theta.cwiseMax(lo).cwiseMin(hi); }

struct Objective {
  const LibraryEffect* effect;
  const FitContext* context;
  const std::vector<int>* rows;
  double penalty;
  int evaluations = 0;
};

double nlopt_objective(unsigned p, const double* x, double* gradient, void* data) {
  static_cast<void>(gradient);  // derivative-free
  auto* o = static_cast<Objective*>(data);
  ++o->evaluations;
  const Eigen::Map<const Vector> theta(x, static_cast<Eigen::Index>(p));
  try {
    bool finite = true;
    const Vector r = weighted_residual_at(*o->effect, theta, *o->context, *o->rows, &finite);
    return finite ? r.squaredNorm() : o->penalty;
  } catch (const std::invalid_argument&) {
    return o->penalty;  // outside what the model accepts (e.g. a mass of 0): a wall for the optimiser
  }
}

/// Held-out scores of theta_hat against the model (step 4).
void score_heldout(const LibraryEffect& effect, const FitContext& c, EffectFit& fit) {
  const std::vector<int> rows = c.data->rows(true);
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Vector before = weighted_model_residual(c, rows);
  const Vector after = weighted_residual_at(effect, fit.estimate, c, rows);
  const Vector sqrt_w = c.weights.cwiseSqrt();
  fit.heldout_rmse_before = Vector::Zero(n);
  fit.heldout_rmse_after = Vector::Zero(n);
  // Batches of consecutive samples of one episode: sums of the reduction d and of the "before" term.
  std::vector<double> d_batches, b_batches;
  double d_total = 0.0, b_total = 0.0;
  int previous_episode = -1, in_batch = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto seg = static_cast<Eigen::Index>(k) * n;
    const Vector rb = before.segment(seg, n), ra = after.segment(seg, n);
    fit.heldout_rmse_before += rb.cwiseQuotient(sqrt_w).cwiseAbs2();
    fit.heldout_rmse_after += ra.cwiseQuotient(sqrt_w).cwiseAbs2();
    const double b = rb.squaredNorm(), d = b - ra.squaredNorm();
    const int episode = c.data->episode[static_cast<std::size_t>(rows[k])];
    if (episode != previous_episode || in_batch == c.batch) {
      d_batches.push_back(0.0);
      b_batches.push_back(0.0);
      in_batch = 0;
      previous_episode = episode;
    }
    d_batches.back() += d;
    b_batches.back() += b;
    ++in_batch;
    d_total += d;
    b_total += b;
  }
  const double count = std::max<double>(1.0, static_cast<double>(rows.size()));
  fit.heldout_rmse_before = (fit.heldout_rmse_before / count).cwiseSqrt();
  fit.heldout_rmse_after = (fit.heldout_rmse_after / count).cwiseSqrt();
  if (b_total <= 0.0) return;
  fit.explained = d_total / b_total;
  // Ratio estimator R = D / B: Var(R) ~ K / (K - 1) sum_b (d_b - R b_b)^2 / B^2.
  const auto K = static_cast<double>(d_batches.size());
  if (K < 2.0) return;
  double spread = 0.0;
  for (std::size_t b = 0; b < d_batches.size(); ++b) {
    const double e = d_batches[b] - fit.explained * b_batches[b];
    spread += e * e;
  }
  const double se = std::sqrt(K / (K - 1.0) * spread) / b_total;
  fit.explained_ci = 1.96 * se;
  fit.z_score = se > 0.0 ? fit.explained / se : (fit.explained > 0.0 ? 1e6 : 0.0);
}

/// The 95% interval at theta_hat (step 3).
void confidence_interval(const LibraryEffect& effect, const FitContext& c, const std::vector<int>& rows,
                         EffectFit& fit) {
  const Matrix J = regressor(effect, fit.estimate, c, rows);
  const Vector r = weighted_residual_at(effect, fit.estimate, c, rows);
  const auto p = J.cols();
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Matrix A = J.transpose() * J;
  const Eigen::LDLT<Matrix> A_ldlt(A);
  const double dof = std::max<double>(1.0, static_cast<double>(J.rows() - p));
  Vector variance = (r.squaredNorm() / dof) * A_ldlt.solve(Matrix::Identity(p, p)).diagonal();
  // Delete-one-episode jackknife, each replicate one Gauss-Newton step from theta_hat.
  std::map<int, std::pair<Matrix, Vector>> per_episode;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int e = c.data->episode[static_cast<std::size_t>(rows[k])];
    auto [it, inserted] = per_episode.try_emplace(e, Matrix::Zero(p, p), Vector::Zero(p));
    const auto Jk = J.middleRows(static_cast<Eigen::Index>(k) * n, n);
    it->second.first += Jk.transpose() * Jk;
    it->second.second += Jk.transpose() * r.segment(static_cast<Eigen::Index>(k) * n, n);
  }
  const Vector g = J.transpose() * r;
  const auto E = static_cast<double>(per_episode.size());
  if (E >= 2.0) {
    std::vector<Vector> replicates;
    Vector mean = Vector::Zero(p);
    for (const auto& [e, sums] : per_episode) {
      const Vector step = (A - sums.first).ldlt().solve(g - sums.second);
      if (!step.allFinite()) continue;
      replicates.push_back(fit.estimate + step);
      mean += replicates.back();
    }
    if (replicates.size() >= 2) {
      mean /= static_cast<double>(replicates.size());
      Vector jack = Vector::Zero(p);
      for (const Vector& t : replicates) jack += (t - mean).cwiseAbs2();
      const auto R = static_cast<double>(replicates.size());
      variance = variance.cwiseMax(jack * (R - 1.0) / R);
    }
  }
  if (!variance.allFinite()) variance.setZero();
  const Vector half = 1.96 * variance.cwiseMax(0.0).cwiseSqrt();
  fit.ci_low = fit.estimate - half;
  fit.ci_high = fit.estimate + half;
}

}  // namespace

double regressor_correlation(const Vector& a, const Vector& b) {
  const double na = a.norm(), nb = b.norm();
  if (na == 0.0 || nb == 0.0 || a.size() != b.size()) return 0.0;
  return std::min(1.0, std::abs(a.dot(b)) / (na * nb));
}

EffectFit fit_effect(const LibraryEffect& effect, const FitContext& c) {
  if (c.data == nullptr) throw std::invalid_argument("fit_effect: no data");
  EffectFit fit;
  fit.effect = effect.name;
  fit.parameters = effect.parameters;
  fit.initial = c.model.current_values(effect);
  const auto p = fit.initial.size();
  const std::vector<int> training = c.data->rows(false);

  // 1. Linear least squares at theta_0.
  const Matrix J = regressor(effect, fit.initial, c, training);
  const Vector r0 = weighted_model_residual(c, training);
  fit.training_objective_before = r0.squaredNorm();
  fit.regressor = J.col(0);
  Vector lower(p), upper(p), scale(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    lower(j) = effect.parameters[static_cast<std::size_t>(j)].lower;
    upper(j) = effect.parameters[static_cast<std::size_t>(j)].upper;
    scale(j) = effect.parameters[static_cast<std::size_t>(j)].scale;
  }
  if (!(J.norm() > 0.0) || !J.allFinite()) {
    fit.identifiable = false;
    fit.linear_estimate = fit.estimate = fit.ci_low = fit.ci_high = fit.initial;
    fit.training_objective_after = fit.training_objective_before;
    score_heldout(effect, c, fit);
    return fit;
  }
  const Vector delta = J.colPivHouseholderQr().solve(r0);
  fit.linear_estimate = clamp_to(fit.initial + delta, lower, upper);

  // 2. Nonlinear refit of S(theta) with NLopt, in a box around theta_LS inside the physical range.
  const Vector radius = 2.0 * delta.cwiseAbs() + 0.05 * scale;
  const Vector lo = (fit.linear_estimate - radius).cwiseMax(lower);
  const Vector hi = (fit.linear_estimate + radius).cwiseMin(upper);
  Objective objective{&effect, &c, &training, 1e30 * (1.0 + fit.training_objective_before)};
  std::vector<double> x(fit.linear_estimate.data(), fit.linear_estimate.data() + p);
  double best = std::numeric_limits<double>::infinity();
  try {
    nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(p));
    opt.set_lower_bounds(std::vector<double>(lo.data(), lo.data() + p));
    opt.set_upper_bounds(std::vector<double>(hi.data(), hi.data() + p));
    opt.set_min_objective(nlopt_objective, &objective);
    opt.set_xtol_abs(std::vector<double>(p, 0.0));
    opt.set_xtol_rel(1e-7);
    opt.set_ftol_rel(1e-12);
    opt.set_maxeval(200);
    std::vector<double> step(static_cast<std::size_t>(p));
    for (Eigen::Index j = 0; j < p; ++j) step[static_cast<std::size_t>(j)] = std::max(0.25 * (hi(j) - lo(j)), 1e-8 * scale(j));
    opt.set_initial_step(step);
    opt.optimize(x, best);
  } catch (const std::exception&) {
    // NLopt gave up (roundoff, invalid step): keep the best point it reported, checked below.
  }
  fit.evaluations = objective.evaluations;
  fit.estimate = Eigen::Map<const Vector>(x.data(), p);
  const double at_linear = nlopt_objective(static_cast<unsigned>(p), fit.linear_estimate.data(), nullptr, &objective);
  const double at_refit = fit.estimate.allFinite()
                              ? nlopt_objective(static_cast<unsigned>(p), fit.estimate.data(), nullptr, &objective)
                              : std::numeric_limits<double>::infinity();
  if (!(at_refit <= at_linear)) fit.estimate = fit.linear_estimate;
  fit.training_objective_after = std::min(at_refit, at_linear);

  // 3. Interval; 4. held-out scores.
  confidence_interval(effect, c, training, fit);
  score_heldout(effect, c, fit);
  return fit;
}

EffectFit score_effect(const LibraryEffect& effect, const VectorCRef& values, const FitContext& c) {
  if (c.data == nullptr) throw std::invalid_argument("score_effect: no data");
  static_cast<void>(c.model.with(effect, values));  // validates the values
  EffectFit fit;
  fit.effect = effect.name;
  fit.parameters = effect.parameters;
  fit.initial = c.model.current_values(effect);
  fit.linear_estimate = fit.estimate = fit.ci_low = fit.ci_high = values;
  const std::vector<int> training = c.data->rows(false);
  fit.training_objective_before = weighted_model_residual(c, training).squaredNorm();
  fit.training_objective_after = weighted_residual_at(effect, values, c, training).squaredNorm();
  score_heldout(effect, c, fit);
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

std::vector<RankedEffect> rank_effects(const FitContext& context, double alias_threshold,
                                       const std::function<void(const std::string&)>& progress) {
  const SystemEntryPtr system = find_system(context.model.system);
  std::vector<EffectFit> fits;
  const std::vector<LibraryEffect> library = candidate_effects(context.model);
  for (const LibraryEffect& effect : library) {
    fits.push_back(fit_effect(effect, context));
    if (progress)
      progress(fmt::format("effect {}/{} fitted: {} explains {:.1f}%", fits.size(), library.size(), fits.back().effect,
                           100.0 * fits.back().explained));
  }
  std::stable_sort(fits.begin(), fits.end(),
                   [](const EffectFit& a, const EffectFit& b) { return a.explained > b.explained; });
  std::vector<bool> used(fits.size(), false);
  std::vector<RankedEffect> out;
  for (std::size_t i = 0; i < fits.size(); ++i) {
    if (used[i]) continue;
    used[i] = true;
    RankedEffect entry{fits[i], {}};
    for (std::size_t j = i + 1; j < fits.size(); ++j) {
      if (used[j]) continue;
      // Aliases: nearly collinear regressors on these data, or the same physics by declaration.
      if (regressor_correlation(fits[i].regressor, fits[j].regressor) < alias_threshold &&
          !same_physics(*system, fits[i].effect, fits[j].effect))
        continue;
      used[j] = true;
      entry.aliases.push_back(fits[j]);
    }
    out.push_back(std::move(entry));
  }
  return out;
}

}  // namespace gpilqg::diagnosis
