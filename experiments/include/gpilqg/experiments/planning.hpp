#pragma once
/// @file planning.hpp
/// `gpilqg plan` as a library call: one round of Algorithm 1 on measurement files (docs/real-robot.md). It builds the simulator and the task of a PlanConfig, reads the data files into labelled
/// transitions (file i is round label i, so the last file holds the newest rollouts, on which the
/// re-sample rule is judged), takes the previous policy file's controls and GP as the warm start, and
/// calls plan_gp_ilqg_round, the step `gpilqg run` takes for gp_ilqg.
///
/// Seeds: `seed` S makes the GP fit draw what `gpilqg run --seeds` seed S draws for gp_ilqg on its
/// first task (run_setup.hpp, gp_fit_seed), so a scripted loop of plan and rollout with the same seed
/// reproduces run's gp_ilqg policies.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "gpilqg/experiments/gp_ilqg_round.hpp"
#include "gpilqg/experiments/loop_diagnosis.hpp"
#include "gpilqg/experiments/plan_config.hpp"
#include "gpilqg/experiments/policy_file.hpp"

namespace gpilqg {

struct PlanRequest {
  PlanConfig config;
  std::vector<std::filesystem::path> data_files;      ///< measurement files (CSV or HDF5), oldest first
  std::optional<std::filesystem::path> previous;      ///< the previous round's policy file
  std::uint64_t seed = 1;
  /// Diagnose the data first (`gpilqg plan --diagnose`, loop_diagnosis.hpp) and, when the verdict is
  /// "explained", plan on the diagnosed model as the simulator.
  bool diagnose = false;
};

struct PlannedPolicy {
  PolicyFile file;                                   ///< what write_policy_file writes
  std::shared_ptr<const gp::ResidualModel> model;    ///< the fitted GP (null: planned on the simulator)
  DdpSummary summary;                                ///< the solver's termination, iterations, timings
  /// Where the solve started (ReferencePlans::start_name): "the usual start" (the previous
  /// policy's open-loop controls or u_init's), "the plan on ..." a simpler model, or "the previous
  /// round's policy" replayed with its feedback (reference_plans.hpp).
  std::string start;
  int data_rows = 0;                                 ///< transitions the GP was fitted on
  double fit_seconds = 0.0;
  bool warm_started_gp = false;                      ///< the previous file's GP was the fit's start
  std::optional<LoopDiagnosis> diagnosis;            ///< with request.diagnose and data
  /// The model the round planned on (the GP's mean): the diagnosed model when the diagnosis adopted
  /// it, else the config's simulator. What `plan --write-model` writes for the next round.
  ModelSpec planned_on;
};

/// The round. Throws DataError or InputError naming the file and the line, dataset or attribute for
/// bad data files (another system, a dt other than the config's) and for a previous policy of
/// another system, dt or horizon, or whose GP backend differs from [gp] backend; and InputError for
/// request.diagnose without data files (nothing to diagnose).
PlannedPolicy plan_policy(const PlanRequest& request);

}  // namespace gpilqg
