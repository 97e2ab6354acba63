#pragma once
/// @file loop_diagnosis.hpp
/// The diagnosis inside GP-ILQG's loop (`gpilqg run` with [diagnosis] after_round = K): after the
/// rollouts of round K, every transition collected so far is diagnosed (`gpilqg diagnose --auto`,
/// diagnosis/diagnosis.hpp) against the run's simulator. When the verdict is "explained", the
/// diagnosed model (the simulator with the effects found, refitted jointly) becomes the simulator from
/// round K + 1 on: the residual GP's mean function, so that the GP learns only what the diagnosis did
/// not name. Any other verdict keeps the simulator and is recorded with its reason. A transfer task
/// starts from the model its previous task adopted.
///
/// The rollouts are the diagnosis's episodes (episodes_of): whole rollouts are held out, and the
/// k-step windows start from measured states, as with a log of the real machine.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/noise.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/step_model.hpp"
#include "gpilqg/experiments/run_config.hpp"
#include "gpilqg/experiments/transition_data.hpp"

namespace gpilqg {

struct LoopDiagnosis {
  /// The round after whose rollouts the data were diagnosed; -1 when the model was adopted by the
  /// previous task (a transfer task starts from it).
  int round = -1;
  /// The diagnosis's verdict ("explained", "partly_explained", "unexplained", "consistent",
  /// "model_diverges"), or "failed" when the data could not be diagnosed (reason says why).
  std::string verdict;
  std::string reason;
  bool adopted = false;         ///< verdict "explained": the plans from round + 1 on use `model`
  ModelSpec model;              ///< the diagnosed model (the simulator when nothing was found)
  std::vector<std::string> changes;  ///< model.describe(): one line per difference from the preset
  double seconds = 0.0;
  int transitions = 0;          ///< the rows diagnosed
};

/// The rollouts in `data` as episodes of a measurement set: a new episode starts where a row's x is not
/// the previous row's x_next (a rollout starts again from its initial state) or the round label changes.
/// Times are k dt.
MeasurementSet episodes_of(const TransitionData& data, const SystemSignature& signature, double dt);

/// The model a loop diagnoses against and how it steps: its simulator, integrator, sub-steps and dt.
struct LoopModel {
  ModelSpec simulator;
  Integrator integrator = Integrator::RK4;
  int substeps = 1;
  double dt = 0.0;
};

/// Diagnoses `data` (episodes_of) against model.simulator with `--auto` and the command's defaults,
/// the GP's random stream seeded by `seed`. Data the diagnosis cannot use (too few rollouts to hold
/// some out, for example) give verdict "failed" with the reason; nothing is thrown for them.
LoopDiagnosis diagnose_loop_data(const LoopModel& model, const TransitionData& data, int round, std::uint64_t seed,
                                 const std::function<void(const std::string&)>& progress = {});

/// A run's LoopModel: its simulator, integrator, sub-steps and control period.
LoopModel loop_model(const RunConfig& config);

/// The step model of the simulator the plans use: the diagnosed model (with `noise`, stepped as
/// `model` says) when `diagnosis` adopted one, else `simulator`.
std::shared_ptr<const StepModel> planning_simulator(const LoopModel& model, const ActuatorNoise& noise,
                                                    const std::shared_ptr<const StepModel>& simulator,
                                                    const std::optional<LoopDiagnosis>& diagnosis);

/// One line for messages and the result file: the verdict, when and on what, and the model's changes
/// with their values, e.g. "explained after round 0 (500 transitions, 3.2 s): cart_coulomb_friction:
/// mu = 1.02 N; pole_length = 0.65 m".
std::string diagnosis_summary(const LoopDiagnosis& diagnosis);

/// The first iteration whose plan used the diagnosed model: round + 1, 0 for an inherited model, -1
/// when none was adopted.
int diagnosed_from(const std::optional<LoopDiagnosis>& diagnosis);

}  // namespace gpilqg
