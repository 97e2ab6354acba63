#include "gpilqg/experiments/diagnosis/criteria/criterion_context.hpp"

#include <stdexcept>

#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/criteria/simulation.hpp"
#include "gpilqg/experiments/diagnosis/initial_state.hpp"

namespace gpilqg::diagnosis {

FitContext criterion_context(FitContext context, FitCriterion criterion, int window, int* restarts) {
  if (window < 1) throw std::invalid_argument("criterion_context: the window must be >= 1 row");
  if (restarts != nullptr) *restarts = 0;
  if (criterion == FitCriterion::InverseDynamics) {
    context.criterion = InverseDynamicsCriterion::make(context);
    return context;
  }
  if (criterion == FitCriterion::OneStep) {
    context.criterion = one_step_criterion();
    return context;
  }
  std::shared_ptr<const InitialStateSensitivity> starts;
  if (context.data != nullptr && context.estimate_starts)
    starts = std::make_shared<const InitialStateSensitivity>(initial_state_sensitivity(
        *make_step_model(context.model, context.integrator, context.dt, context.substeps), *context.data,
        applied_controls(*context.data, context.model.input_delay), window, context.weights));
  context.criterion = std::make_shared<const SimulationCriterion>(window, std::move(starts));
  if (context.data != nullptr) context.residual = context.criterion->residual(context.model, context, restarts);
  return context;
}

}  // namespace gpilqg::diagnosis
