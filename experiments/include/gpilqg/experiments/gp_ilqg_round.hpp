#pragma once
/// @file gp_ilqg_round.hpp
/// One round of the paper's Algorithm 1 on measured transitions: the planning step that `gpilqg run`
/// (algorithm gp_ilqg) and `gpilqg plan` (one round on a real robot's logs) both call.
///
///  - No data: iLQG on the simulator alone (Robust-iLQG without the GP's G is iLQG), the paper's
///    iteration 0.
///  - Data: the residual GP learns the simulator's one-step error on every transition, z = [x; u] ->
///    x' - phi_sim(x, u) (gp/residual_model.hpp). With the previous round's GP it is warm-started
///    from that GP's hyperparameters and the paper's re-sample rule decides, on the newest rows (the
///    rows with the largest round label), whether the previous training points are kept
///    (gp/resample.hpp). No output may fit a noise std below what the sensors and the process noise
///    put into its targets (gp/noise_floor.hpp). Then Robust-iLQG (F and G = diag(sigma(z))) or, as an ablation, iLQG on the
///    GP mean solves the task on simulator + GP, warm-started from the previous round's controls.
///  - Either way each of `plans_to_keep` (plans on simpler models and the previous round's policy,
///    reference_plans.hpp) is a further start of the solve, which begins at the start of least cost on
///    the round's model.

#include <memory>
#include <vector>

#include "gpilqg/experiments/task_actions.hpp"
#include "gpilqg/experiments/transition_data.hpp"
#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/fit.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {

struct GpRoundInputs {
  const TransitionData* data = nullptr;  ///< every transition so far, labelled by round
  const gp::GpBackend* backend = nullptr;
  std::shared_ptr<const gp::ResidualModel> previous_model;  ///< the previous round's GP (null: none)
  Matrix previous_u_bar;  ///< the previous round's nominal controls, m x T (empty: task.u_init)
  gp::FitOptions fit;     ///< seed, restarts and evaluations of the hyperparameter fit
  DdpVariant variant = DdpVariant::RobustILQG;  ///< with data: RobustILQG (the paper) or ILQG (GP mean)
  int threads = 2;        ///< threads fitting the GP's outputs concurrently (the results do not depend on it)
  /// The sensors' noise std per state (empty: none). With the simulator's process noise it sets every
  /// output's floor on the fitted noise std (gp/noise_floor.hpp).
  Vector observation_std;
  /// GpSettings::known_noise: the sensors' and the simulator's process noise at each transition as a
  /// known noise variance per point (gp::backends_taking_known_noise); false: their least value as a floor.
  bool known_noise = false;
  /// Plans that this round's plan must not lose to (reference_plans.hpp: simpler models' plans, the
  /// previous round's policy): each is a further start of the solve, which begins at the start of
  /// least cost on the round's model.
  std::vector<AffinePolicy> plans_to_keep;
};

struct GpRound {
  Plan plan;  ///< plan.model is the simulator (no data) or the fitted gp::ResidualModel
  double fit_seconds = 0.0;
  std::vector<Vector> hyperparameters;  ///< per state: [log l (n+m); log sf; log sn] (empty: no GP)
  Vector noise_floor;                   ///< per state: the floor on sn the fit used (empty: no GP)
};

/// The round (see the file comment). Throws std::invalid_argument for inconsistent inputs (data of
/// another size than the simulator's, a previous u_bar of another shape).
GpRound plan_gp_ilqg_round(const DdpTask& task, const std::shared_ptr<const StepModel>& simulator,
                           const GpRoundInputs& inputs);

}  // namespace gpilqg
