#include "gpilqg/experiments/diagnosis/criteria/one_step.hpp"

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/residual_analysis.hpp"

namespace gpilqg::diagnosis {

Matrix OneStepCriterion::residual(const ModelSpec& model, const FitContext& c, int* diverged) const {
  return c.data->x_next - predictions(model, c, diverged);
}

Vector OneStepCriterion::weighted_residual(const ModelSpec& model, const FitContext& c, const std::vector<int>& rows,
                                           bool* finite) const {
  const auto step = make_step_model(model, c.integrator, c.dt, c.substeps);
  const Matrix u = applied_controls(*c.data, model.input_delay);
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Vector sqrt_w = c.weights.cwiseSqrt();
  Vector out(static_cast<Eigen::Index>(rows.size()) * n);
  Vector next(n);
  const auto workspace = step->make_workspace();
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int r = rows[k];
    step->step(c.data->x.row(r).transpose(), u.row(r).transpose(), next, nullptr, *workspace);
    // A diverged prediction (not finite or beyond 1e12) counts as x_t, so its square cannot overflow.
    if (prediction_diverged(next)) {
      if (finite != nullptr) *finite = false;
      next = c.data->x.row(r).transpose();
    }
    out.segment(static_cast<Eigen::Index>(k) * n, n) = sqrt_w.cwiseProduct(c.data->x_next.row(r).transpose() - next);
  }
  return out;
}

double OneStepCriterion::flexible_share(const ModelSpec&, const OneStepGp* gp, const FitContext& c,
                                        const GpSettings&) const {
  return weighted_heldout_explained(*c.data, gp->residual, gp->gp.mean, c.weights);
}

}  // namespace gpilqg::diagnosis
