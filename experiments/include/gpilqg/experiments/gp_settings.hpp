#pragma once
/// @file gp_settings.hpp
/// The `[gp]` table that `gpilqg run` and `gpilqg plan` share: which backend learns the simulator's
/// error and how hard its hyperparameters are fitted (docs/formats.md#run-config-gpilqg-run,
/// docs/real-robot.md#the-plan-config).
///
///   [gp]  backend ("exact"|"fitc"|"ssgp"|"compact"), exact_points, inducing, frequencies,
///         restarts, max_evaluations, known_noise

#include <string>

#include "gpilqg/gp/backend_registry.hpp"

namespace gpilqg {

class TomlFields;

struct GpSettings {
  std::string backend = "exact";
  gp::BackendSettings backend_settings;  ///< sizes of the backends (exact_points, inducing, frequencies)
  int restarts = 1;                      ///< random restarts of the hyperparameter fit, beside the data-driven start
  int max_evaluations = 150;             ///< NLopt evaluations per start
  /// Each residual GP takes the noise the simulator itself predicts at each transition (the sensors'
  /// and its process noise, gp/noise_floor.hpp) as a known noise variance per point and learns only
  /// the rest (TrainingSet::noise_variance); false: one learned noise level per output with that
  /// noise's least value as its floor. The backends of gp::backends_taking_known_noise (not compact).
  bool known_noise = false;
};

/// Reads [gp] through `f` (errors name the file, line and field); a field the table lacks takes its
/// value from `defaults`. The backend name and sizes are checked by building the backend once.
GpSettings read_gp_settings(const TomlFields& f, const GpSettings& defaults);

}  // namespace gpilqg
