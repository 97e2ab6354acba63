#pragma once
/// @file simulation.hpp
/// The simulation criterion (output error, MATLAB's `oe`/`pem`): the state simulated over windows of
/// W samples from each window's start (simulation_error.hpp), the start estimated to first order
/// about the measured one (initial_state.hpp) so that the sensor noise of one sample does not grow
/// along the window. Sees effects whose one-step change is below the noise (light damping), since
/// their effect accumulates over the window.

#include <memory>

#include "gpilqg/experiments/diagnosis/criteria/criterion.hpp"
#include "gpilqg/experiments/diagnosis/initial_state.hpp"

namespace gpilqg::diagnosis {

class SimulationCriterion final : public Criterion {
 public:
  /// Windows of `window` >= 1 rows (1: the one-step error); `starts` the sensitivities of the base model's windows to their
  /// starts (null: every window from its measured start).
  SimulationCriterion(int window, std::shared_ptr<const InitialStateSensitivity> starts);

  FitCriterion kind() const override { return FitCriterion::Simulation; }
  int window() const override { return window_; }
  /// The sensitivities whose first-order effect every simulation error leaves out, or null.
  const InitialStateSensitivity* start_sensitivity() const { return starts_.get(); }

  Matrix predictions(const ModelSpec& model, const FitContext& c, int* diverged = nullptr) const override;
  std::string scored_on() const override;
  Matrix residual(const ModelSpec& model, const FitContext& c, int* diverged = nullptr) const override;
  Vector weighted_residual(const ModelSpec& model, const FitContext& c, const std::vector<int>& rows,
                           bool* finite = nullptr) const override;
  /// The same share with the simulation errors of `model` and of the GP-corrected model over the
  /// criterion's windows, the starts' first-order error left out of both.
  double flexible_share(const ModelSpec& model, const OneStepGp* gp, const FitContext& c,
                        const GpSettings& settings) const override;
  std::string starts() const override { return starts_ ? "estimated" : "measured"; }
  std::string description(double dt, int restarts) const override;

 private:
  int window_;
  std::shared_ptr<const InitialStateSensitivity> starts_;
};

}  // namespace gpilqg::diagnosis
