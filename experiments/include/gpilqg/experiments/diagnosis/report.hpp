#pragma once
/// @file report.hpp
/// The diagnosis as a terminal report and as one JSON document
/// (docs/formats.md#diagnosis-json-gpilqg-diagnose---json: the keys "system", "samples",
/// "heldout_episodes", "consistent", "states", "relevance", "ranking", "verdict" are fixed; the others
/// are additions).
///
/// Ranking entries carry "heldout_rmse_before" / "heldout_rmse_after" for one state, "heldout_state":
/// the state whose held-out RMSE is furthest above its noise floor under the diagnosed model (the same
/// state for every entry, so the numbers compare); per-state values are in "heldout_rmse_by_state".

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "gpilqg/experiments/diagnosis/diagnosis.hpp"

namespace gpilqg::diagnosis {

/// Index of the state whose held-out RMSE / noise floor is largest.
int worst_state(const DiagnosisReport& report);

/// The channel of the criterion (DiagnosisReport::channel_names) the reports single out for the
/// effects' held-out RMSE: worst_state for the state criteria; under inverse dynamics the force
/// component whose weighted held-out residual is largest before the best-ranked effect (0 when nothing
/// is ranked).
int worst_channel(const DiagnosisReport& report);

/// The whole report as JSON. Every number is finite.
nlohmann::json report_json(const DiagnosisReport& report);

/// The readable report: compare, where, which, add, verdict and the next step. Ends with a newline.
std::string report_text(const DiagnosisReport& report);

}  // namespace gpilqg::diagnosis
