#pragma once
/// @file set_residual.hpp
/// The weighted criterion residual of a set of effects as a function of their stacked parameters,
/// and its regressor: what every fit of effect_fit.cpp evaluates.
///
/// In general the model is rebuilt at every theta (ModelSpec::with) and the regressor is taken by
/// central differences, two evaluations of the model per parameter. Under the inverse-dynamics
/// criterion with forces linear in their parameters there is the closed form
/// r(theta) = r(theta_0) - G (theta - theta_0) with the exact regressor sqrt(w) G
/// (affine_force_residual.hpp), built once from theta_0; with parameters of the model (a mass, an
/// armature, a damping) the same closed form, its columns the secants of probes of the model, when
/// the data show the residual to be affine in them. Both give the same numbers up to rounding.
///
/// The evaluations of one regressor, and the probes, are independent: FitContext::threads of them
/// run at once.

#include <deque>
#include <optional>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/experiments/diagnosis/affine_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

namespace gpilqg::diagnosis {

/// The effects of one fit with their parameters stacked, theta = [theta_1; ...; theta_E]; the
/// candidate is effects[0], so column 0 of the regressor is its first parameter.
struct EffectSet {
  std::vector<const LibraryEffect*> effects;
  std::vector<Eigen::Index> offset{0};  ///< E + 1 entries: effect e owns theta[offset[e], offset[e + 1])

  void add(const LibraryEffect& effect);
  Eigen::Index size() const { return offset.back(); }
  /// True when every effect is linear in its parameters (LibraryEffect::linear).
  bool linear() const;
  Eigen::Index length(std::size_t e) const { return offset[e + 1] - offset[e]; }
  const EffectParameter& parameter(Eigen::Index j) const;
  /// Every effect's value in `base` (ModelSpec::current_values): the stacked values without the set.
  Vector null_values(const ModelSpec& base) const;
  /// `base` with every effect of the set at its slice of theta (ModelSpec::with, which validates); a
  /// value past its bound by at most 1e-3 of the parameter's bounds or scale (a difference step's
  /// rounding at the bound) is taken at the bound.
  ModelSpec model_at(const ModelSpec& base, const VectorCRef& theta) const;

  /// The stacked parameters split by how their regressor columns are found: those of the forces
  /// linear in their parameters (their bases, weighted_force_regressor) and the others (the model
  /// evaluated at a moved theta).
  struct Columns {
    std::vector<const LibraryEffect*> forces;
    std::vector<Eigen::Index> force_columns, others;
  };
  /// `with_forces` false: every parameter is among the others (no criterion with the forces' bases).
  Columns columns(bool with_forces) const;
};

/// The residual of a set of effects and its regressor (file comment). One per fit; not to be shared
/// between threads (it keeps its last evaluations).
class SetResidual {
 public:
  /// `probe`: under inverse dynamics, try the closed form for sets with parameters of the model too
  /// (probed_affine_residual); the fit checks it again at its estimate (matches_at).
  SetResidual(const EffectSet& set, const Vector& theta0, const FitContext& c, bool probe = true);

  /// True when the closed form stands on probes of the model (not only on forces linear by construction).
  bool probed() const { return probed_; }
  /// Whether the rebuilt model's residual at theta equals the closed form's on every row, to rounding
  /// (affine_to_rounding). True when there is no probed closed form.
  bool matches_at(const VectorCRef& theta) const;

  /// sqrt(w) r at theta stacked over `rows`; `finite` as in Criterion::weighted_residual. The fit asks
  /// for the same point several times (the start, the accepted Gauss-Newton step, the interval's
  /// point): the last few evaluations of the rebuilt model are kept.
  Vector at(const VectorCRef& theta, const std::vector<int>& rows, bool* finite = nullptr) const;

  /// Weighted regressor d phi / d theta at theta (rows.size() k x p): by central differences (one-sided
  /// when the lower step would leave the physical range), or the closed form's. Under inverse dynamics
  /// the columns of forces linear in their parameters are their weighted bases in the model at theta,
  /// exactly (affine_force_residual.hpp), beside the differences of the other effects.
  Matrix regressor(const VectorCRef& theta, const std::vector<int>& rows) const;

 private:
  /// One evaluation of the rebuilt model's residual (or regressor) at theta on `rows`.
  struct Evaluation {
    Vector theta;
    std::vector<int> rows;
    Matrix value;
    bool finite = true;
  };
  /// Keeps `e` among the last kKept evaluations of its kind; returns it.
  static const Evaluation& remember(std::deque<Evaluation>& kept, Evaluation e);

  /// The rebuilt model's residual at each of `thetas` on `rows`, FitContext::threads at once.
  /// Throws what the model throws (std::invalid_argument outside the physical range).
  std::vector<Vector> rebuilt(const std::vector<Vector>& thetas, const std::vector<int>& rows) const;

  /// The closed form r(theta) = r(theta0) - G (theta - theta0) of affine_force_residual.hpp for a set
  /// with effects other than linear forces, when the data show it to be affine: the columns of the
  /// linear forces are their bases; the column of every other parameter j is the secant
  /// (r(theta0) - r(theta0 + s_j e_j)) / s_j of the rebuilt model at a step of its scale s_j. The
  /// closed form must then predict the rebuilt model at theta0 + 2 s (every parameter moved, forces by
  /// their scale) to rounding; otherwise, or when a probe leaves the physical range, none (the rebuilt
  /// model at every theta). Costs 2 + (parameters that are not linear forces) evaluations of the model.
  std::optional<AffineForceResidual> probed_affine_residual(const Vector& theta0);

  const EffectSet& set_;
  const FitContext& c_;
  std::optional<AffineForceResidual> affine_;
  bool probed_ = false;
  Vector theta0_;
  mutable std::deque<Evaluation> residuals_, regressors_;
};

}  // namespace gpilqg::diagnosis
