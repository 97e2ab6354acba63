#pragma once
/// @file one_step.hpp
/// The one-step criterion (equation error): e_t = x_{t+1} - phi(x_t, u_t), the state one model step
/// after the measured state. The default of least-squares identification of sampled models; biased
/// when the regressors (the measured states) are noisy or filtered (errors in variables), and blind to
/// effects whose one-step change is below the noise (simulation_error.hpp says why). Its flexible
/// model is the GP of the one-step residual itself, so the GP's share is comparable with an effect's.

#include "gpilqg/experiments/diagnosis/criteria/criterion.hpp"

namespace gpilqg::diagnosis {

class OneStepCriterion final : public Criterion {
 public:
  FitCriterion kind() const override { return FitCriterion::OneStep; }
  std::string scored_on() const override { return "the one-step residual"; }
  Matrix residual(const ModelSpec& model, const FitContext& c, int* diverged = nullptr) const override;
  Vector weighted_residual(const ModelSpec& model, const FitContext& c, const std::vector<int>& rows,
                           bool* finite = nullptr) const override;
  bool scored_like_the_gp() const override { return true; }
  /// 1 - sum_w (r - mu)^2 / sum_w r^2 with mu the GP's mean.
  double flexible_share(const ModelSpec& model, const OneStepGp* gp, const FitContext& c,
                        const GpSettings& settings) const override;
};

}  // namespace gpilqg::diagnosis
