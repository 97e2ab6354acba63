#pragma once
/// @file policy_file.hpp
/// The policy file of `gpilqg plan` (docs/formats.md, "Policy file", a fixed contract): what a robot's
/// controller runs, and what the next round warm-starts from.
///
///   /policy/x_bar   (T+1) x n   the planned nominal states
///   /policy/u_bar   T x m       the nominal controls
///   /policy/K       T x m x n   the feedback gains
///   /policy attributes: dt, horizon, system, state_names, control_names, u_min and u_max (when
///     limited), predicted_cost, expected_cost, round, data_files, created, gpilqg_version,
///     simulator_model (the simulator planned on, as the text of a model file of `gpilqg diagnose`)
///   /model          the fitted residual GP in gp_io's layout (absent for a plan on the simulator alone)
///
/// The control law at step t with the measured state x_t:
///     u_t = clamp(u_bar_t + K_t (x_t - x_bar_t), u_min, u_max).
/// Arrays are float64 in row-major order, so h5py reads x_bar with shape (T+1, n).

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gpilqg/control/policy.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {

struct PolicyFile {
  AffinePolicy policy;  ///< x_bar n x (T+1), u_bar m x T, K (T of m x n), k = 0, limits (empty: none)
  double dt = 0.0;
  std::string system;   ///< the system's name as the registry knows it (a model file's path for MuJoCo)
  std::vector<std::string> state_names, control_names;
  double predicted_cost = 0.0;  ///< the cost of x_bar, u_bar on the planning model
  double expected_cost = 0.0;   ///< the solver's expected cost, with the model's noise (F and G)
  int round = 0;                ///< 0: planned on the simulator alone; r: the r-th round with data
  std::vector<std::string> data_files;  ///< the measurement files the GP was fitted on, in order
  std::string created;          ///< UTC, ISO 8601
  std::string gpilqg_version;
  /// The simulator the plan used (the GP's mean) as model file text (diagnosis/model_file.hpp); empty
  /// in files of older versions. A warm start of the GP needs the same simulator.
  std::string simulator_model;
  std::string model_backend;    ///< on reading: the backend of /model ("" when there is none)
};

/// An affine policy as the file stores it: the feed-forward k folded into u_bar (u_bar + k), so that
/// the file's law above reproduces AffinePolicy::control exactly.
AffinePolicy file_policy(const AffinePolicy& policy);

/// Writes the file atomically (atomic_file.hpp): the policy and, when `model` is not null, /model,
/// into a temporary file renamed into place, so a reader never sees half a policy. Throws
/// std::invalid_argument for inconsistent shapes or non-finite entries, before anything is written.
void write_policy_file(const std::filesystem::path& file, const PolicyFile& policy, const gp::ResidualModel* model);

/// Reads and checks a policy file: every dataset and attribute above, shapes consistent with each
/// other and with the names, every number finite (x_bar, u_bar, K, dt > 0, the costs, the limits),
/// u_min <= u_max entry by entry, round a whole number >= 0, system and the names not empty. Throws
/// InputError naming the file and the dataset or attribute (and the first bad entry).
PolicyFile read_policy_file(const std::filesystem::path& file);

/// Throws InputError unless the system of `policy` (read from `file`) is `system`, the one it is used
/// for: the same name, or for a MuJoCo model a model file of the same file name (the file stores the
/// path the planner used): "p.h5: attribute '/policy@system' is 'quadrotor'; expected 'cartpole', the
/// system it is used for". Callers compare the state and control names first, the more telling check.
void check_policy_system(const PolicyFile& policy, const std::filesystem::path& file, const std::string& system);

/// The file's /model rebuilt around `simulator` (its stored backend, sized by `settings`). Throws
/// InputError naming the file when there is no /model or it does not fit the simulator.
std::shared_ptr<const gp::ResidualModel> read_policy_model(const std::filesystem::path& file,
                                                           std::shared_ptr<const StepModel> simulator,
                                                           const gp::BackendSettings& settings);

/// The same content as JSON: {"policy": {"x_bar": [[...] x n] x (T+1), "u_bar": T x m, "K": T x m x n,
/// and every attribute}, "model": null or {"backend", "points", "hyperparameters": per state
/// [log l..., log sf, log sn]}}. Arrays nest in the file's row-major order.
nlohmann::json policy_json(const PolicyFile& policy, const gp::ResidualModel* model);


}  // namespace gpilqg
