#pragma once
/// @file run_results_io.hpp
/// The result file of `gpilqg run` (docs/formats.md, "Results file of `gpilqg run`", documents it with an
/// h5py example). S seeds, K + 1 iterations, E evaluation rollouts, T steps, n states, m controls,
/// D = n + m GP inputs; every dataset is float64:
///
///   /                       attrs: schema_version (1), gpilqg_version, config (full TOML), seed (first),
///                           created (UTC, ISO 8601), system
///   /seeds                  (S)
///   /<task>                 attrs: algorithms (names in run order), transfer (0/1), horizon, dt
///   /<task>/data/{x, u, dx} (N x n, N x m, N x n): the real-world transitions gp_ilqg collected, all
///                           seeds and iterations, measured (dx = x' - x); plus seed (N), iteration (N)
///   /<task>/<algorithm>/cost             (K+1 x S) mean real-world cost of each iteration's policy
///   /<task>/<algorithm>/normalised_cost  (K+1 x S) cost / ilqg_real's cost of the same seed
///   /<task>/<algorithm>/evaluation_costs (K+1 x S x E) the single rollouts behind `cost`
///   /<task>/<algorithm>/{time_fit, time_solve, time_rollouts, time_evaluation} (K+1 x S) [s]
///   /<task>/<algorithm>/{data_rows, repeated, diverged, policy_change} (K+1 x S); converged_at (S), -1: never
///   /<task>/<algorithm>/iter_<k>/x (S x n x T+1), u (S x m x T): the plan's nominal trajectory
///   /<task>/<algorithm>/iter_<k>/K (S x T x m x n), k (S x m x T): its feedback and feed-forward
///   /<task>/<algorithm>/iter_<k>/{predicted_cost, solve_time} (S)
///   /<task>/<algorithm>/iter_<k>/{eval_x, eval_u} (S x n x T+1, S x m x T): the first evaluation rollout
///   /<task>/<algorithm>/{diagnosed_from, diagnosis_round} (S): with the diagnosis inside the loop
///                           ([diagnosis] after_round), the first iteration planned on the diagnosed
///                           model and the round whose data were diagnosed (-1: none, or a model the
///                           previous task adopted); attrs of diagnosed_from: diagnosis (S texts:
///                           verdict, what was found, when, the values), model (S model files; "" if none)
///   /<task>/<algorithm>/gp/<state>/hyper (K+1 x S x D+2): [log l; log sf; log sn], zeros where
///                           gp/<state>/fitted (K+1 x S) is 0 (no GP yet); gp_ilqg algorithms only
///   /<task>/figure1/...     the 1-D model slice (the paper's Figure 1), model_slice_io.hpp
///   /<task>/gp_ilqg         a soft link to gp_ilqg_<first backend> when GP backends are compared
///
/// The file is written to a temporary name in the same folder and renamed into place, so a reader
/// never sees a half-written result and an interrupted write leaves any previous file intact.
///
/// Where the seeds are: every dataset of an algorithm's group holds one slice per seed along the axis
/// seed_axis() names; /<task>/data holds each row's seed in data/seed; /<task>/figure1 is the first
/// seed's. Files of disjoint seeds join along these axes (`gpilqg merge`, run_merge.hpp).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>

#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/experiments/run_experiment.hpp"

namespace gpilqg {

/// The root's schema_version: the version of the layout above.
inline constexpr std::int64_t kRunResultsSchemaVersion = 2;

/// The axis along which a dataset of /<task>/<algorithm>/ holds one slice per seed, the one table
/// of it that the writer's layout and `gpilqg merge` share. `dataset` is relative to the algorithm's
/// group ("cost", "iter_3/K", "gp/theta/hyper"):
///   axis 1: the (K+1 x S) matrices (cost, normalised_cost, time_*, data_rows, repeated, diverged,
///           policy_change), evaluation_costs (K+1 x S x E), gp/<state>/hyper (K+1 x S x D+2) and
///           gp/<state>/fitted (K+1 x S);
///   axis 0: converged_at, diagnosed_from, diagnosis_round (S) and every iter_<k>/ dataset (S x ...).
/// std::nullopt: not a dataset of this layout (a file of another gpilqg version).
std::optional<std::size_t> seed_axis(std::string_view dataset);

/// Whether the dataset of an algorithm's group (named as for seed_axis) measures wall-clock time
/// (time_fit, time_solve, time_rollouts, time_evaluation, iter_<k>/solve_time): the only numbers
/// in which two runs of the same seed and config may differ.
bool is_wall_clock_time(std::string_view dataset);

/// Writes `results` atomically. Throws std::runtime_error naming the file when writing fails.
void write_run_results(const std::filesystem::path& file, const RunResults& results);

/// The same layout below the group `root` ("" for the file's root; "/point_3" for a grid point of
/// `gpilqg sweep`), the root attributes on that group.
void write_run_results_to(Hdf5Writer& h5, const std::string& root, const RunResults& results);

}  // namespace gpilqg
