#pragma once
/// @file run_merge.hpp
/// `gpilqg merge`: result files of `gpilqg run` (run_results_io.hpp) joined into one file of the same
/// layout, as if one run had computed them all. The parts are runs of one experiment for disjoint
/// seeds (cluster jobs: `gpilqg run SYSTEM --first-seed $ID --seeds 1`), or for the same seeds with
/// different algorithms (different --backends); every dataset of an algorithm is joined along its
/// seed axis (seed_axis()), with the seeds in ascending order.
///
/// The merged file:
///  - root attributes of the parts (all equal), `seed` the smallest seed, `created` now; /seeds sorted;
///  - per task, the algorithms in the order of the first part that has them, then those that only
///    later parts have, in their order; transfer, horizon, dt as in the parts;
///  - /<task>/data: each seed's rows from a part whose /<task>/data belongs to the task's main GP
///    algorithm (what /<task>/gp_ilqg links to, or gp_ilqg), in ascending seed order;
///  - /<task>/figure1 from the part that gave the smallest seed's rows (a run draws it from its first
///    seed); the soft link /<task>/gp_ilqg as in the first part that has one.
/// A seed of an algorithm held by two parts is kept once when the two copies are equal in every
/// dataset but the wall-clock times (is_wall_clock_time()): runs with different --backends share
/// their identical ilqg_real and ilqg_sim.
///
/// Refused with an InputError naming the files and the field: fewer than two parts, a part given
/// twice, an output that is one of the parts; a part that is not a result file of this layout; parts
/// whose config differs (the first differing field, as a dotted path with both values) or whose
/// system, schema_version or gpilqg_version differ; parts whose config named files that read
/// differently (`model_files`: the file and line of the first difference); datasets of an algorithm that differ in more than
/// the seed axis between parts (e.g. another --iterations); a seed of an algorithm held by two parts
/// with different values; an algorithm that would not have every seed of the merged file.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gpilqg {

struct MergedTask {
  std::string name;
  std::vector<std::string> algorithms;  ///< in the merged file's order
  std::size_t data_rows = 0;            ///< rows of /<task>/data
};

struct MergeSummary {
  std::size_t parts = 0;
  std::vector<std::uint64_t> seeds;  ///< ascending
  std::vector<MergedTask> tasks;
};

/// Joins `parts` (see the file comment) into `out`, written atomically (atomic_file.hpp): `out` is
/// never half-written and stays as it was when the merge is refused or fails.
MergeSummary merge_run_results(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out);

}  // namespace gpilqg
