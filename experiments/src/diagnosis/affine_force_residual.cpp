#include "gpilqg/experiments/diagnosis/affine_force_residual.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"

namespace gpilqg::diagnosis {

namespace {

/// The blocks of `rows` (k consecutive entries each) of `all`, a matrix stacked over every row of the data.
Matrix stacked_rows(const Matrix& all, Eigen::Index k, const std::vector<int>& rows) {
  Matrix out(static_cast<Eigen::Index>(rows.size()) * k, all.cols());
  for (std::size_t i = 0; i < rows.size(); ++i)
    out.middleRows(static_cast<Eigen::Index>(i) * k, k) = all.middleRows(static_cast<Eigen::Index>(rows[i]) * k, k);
  return out;
}

}  // namespace

bool linear_forces(const std::vector<const LibraryEffect*>& effects) {
  return std::all_of(effects.begin(), effects.end(), [](const LibraryEffect* e) {
    return e != nullptr && e->kind == EffectKind::Force && e->force != nullptr && e->force->linear_in_parameters();
  });
}

Matrix weighted_force_regressor(const ModelSpec& model, const std::vector<const LibraryEffect*>& effects,
                                const FitContext& c, const std::vector<int>& rows) {
  if (!linear_forces(effects))
    throw std::invalid_argument("weighted_force_regressor: every effect must be a force linear in its parameters");
  const DynamicsPtr system = model.build();
  const Dynamics& owner = force_map_system(*system);
  const auto workspace = owner.make_workspace();
  const InverseDynamicsCriterion* criterion = c.criterion->inverse_dynamics();
  if (criterion == nullptr) throw std::invalid_argument("weighted_force_regressor: the context is not inverse dynamics");
  const Matrix u = applied_controls(*c.data, model.input_delay);
  const Vector sqrt_w = c.weights.cwiseSqrt();
  const Eigen::Index k = sqrt_w.size();
  Eigen::Index p = 0;
  for (const LibraryEffect* e : effects) p += static_cast<Eigen::Index>(e->parameters.size());
  // The bases g_j (sampled x k each, side by side: column j k + i is component i of g_j) at every
  // sample a window of `rows` reaches (all rows when the criterion filters), then seen as the
  // residual sees the model's forces (InverseDynamicsCriterion::filtered), all in one pass.
  const bool filtering = criterion->acceleration_window() > 0;
  const std::vector<int> sampled = filtering ? all_rows(*c.data) : rows;
  Matrix bases(static_cast<Eigen::Index>(sampled.size()), p * k);
  // The unit parameter vectors e_j of each effect, made once rather than per row.
  std::vector<std::vector<Vector>> units;
  for (const LibraryEffect* e : effects) {
    const auto size = static_cast<Eigen::Index>(e->parameters.size());
    units.emplace_back();
    for (Eigen::Index j = 0; j < size; ++j) units.back().push_back(Vector::Unit(size, j));
  }
  Vector x(system->state_dim()), u_t(system->control_dim()), Q(k);
  for (std::size_t i = 0; i < sampled.size(); ++i) {
    x = c.data->x.row(sampled[i]).transpose();
    u_t = u.row(sampled[i]).transpose();
    Eigen::Index column = 0;
    for (std::size_t e = 0; e < effects.size(); ++e) {
      for (const Vector& unit : units[e]) {  // g_j = Q_e(x, u; e_j), Q_e linear in theta
        Q.setZero();
        effects[e]->force->add_force(x, u_t, unit, Q, nullptr, nullptr, *workspace);
        bases.block(static_cast<Eigen::Index>(i), column, 1, k) = Q.transpose();
        column += k;
      }
    }
  }
  Matrix seen = filtering ? criterion->filtered(*c.data, bases, rows) : bases;
  if (!filtering) criterion->leave_out_standstill(seen, rows);
  Matrix out(static_cast<Eigen::Index>(rows.size()) * k, p);
  for (Eigen::Index i = 0; i < seen.rows(); ++i)
    for (Eigen::Index j = 0; j < p; ++j)
      out.block(i * k, j, k, 1) = sqrt_w.cwiseProduct(seen.row(i).segment(j * k, k).transpose());
  return out;
}

AffineForceResidual::AffineForceResidual(const ModelSpec& model, const std::vector<const LibraryEffect*>& effects,
                                         const Vector& theta0, const FitContext& c)
    : theta0_(theta0), k_(c.weights.size()) {
  const std::vector<int> rows = all_rows(*c.data);
  residual_ = weighted_residual_of(model, c, rows);
  regressor_ = weighted_force_regressor(model, effects, c, rows);
  if (regressor_.cols() != theta0.size())
    throw std::invalid_argument("AffineForceResidual: theta0 does not have one entry per parameter of the effects");
}

AffineForceResidual::AffineForceResidual(Vector theta0, Eigen::Index k, Vector residual, Matrix regressor)
    : theta0_(std::move(theta0)), k_(k), residual_(std::move(residual)), regressor_(std::move(regressor)) {
  if (k_ <= 0 || residual_.size() % k_ != 0 || regressor_.rows() != residual_.size() || regressor_.cols() != theta0_.size())
    throw std::invalid_argument(
        "AffineForceResidual: expected a residual of N k entries and a regressor of N k rows and one column per "
        "parameter");
}

Vector AffineForceResidual::weighted(const VectorCRef& theta, const std::vector<int>& rows) const {
  return stacked_rows(residual_, k_, rows) - weighted_regressor(rows) * (theta - theta0_);
}

Matrix AffineForceResidual::weighted_regressor(const std::vector<int>& rows) const {
  return stacked_rows(regressor_, k_, rows);
}

}  // namespace gpilqg::diagnosis
