#pragma once
/// @file measurements_internal.hpp
/// Pieces shared by the CSV and HDF5 readers and writers of measurement data (private to core):
/// the checks of one episode's values, the expected column names, and atomic writing.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg::measurements_detail {

/// Relative tolerance on dt within an episode (docs/formats.md#measurement-data-csv-and-hdf5).
inline constexpr double kDtRelativeTolerance = 1e-6;

/// A problem at one sample of an episode: `index` is the 0-based sample (row) index within the
/// episode, `problem` says what is wrong and `expected` what was expected.
struct SampleIssue {
  Eigen::Index index = 0;
  std::string problem;
  std::string expected;
};

/// Checks one step of an episode's times: `current` (t[i]) must exceed `previous` (t[i-1]), and the
/// step must be within kDtRelativeTolerance of `first_step` (t[1] - t[0]; pass current - previous
/// for i = 1). The returned issue's index is 0: the caller knows where the step is.
std::optional<SampleIssue> check_step(double previous, double current, double first_step);

/// The issue of an episode with fewer than 2 samples (dt undefined), at index 0. The problem text
/// starts with "has N samples", for the caller to name the episode.
SampleIssue too_few_samples(Eigen::Index count);

/// Checks the times of one episode: at least 2 samples (1 sample leaves dt undefined), strictly
/// increasing, and every step t[i] - t[i-1] within kDtRelativeTolerance of the first step t[1] - t[0].
/// Values are assumed finite (checked before). Returns the first problem, or nullopt.
std::optional<SampleIssue> check_times(const Vector& t);

/// "episode", "t", then the state names, then the control names: the CSV header.
std::vector<std::string> expected_columns(const SystemSignature& system);

/// The names joined with `separator`, e.g. "x, x_dot".
std::string join(const std::vector<std::string>& names, const std::string& separator = ", ");

/// The shortest text that reads back as the same double (what the writers put in files).
std::string format_number(double value);

/// Checks that a set is fit to be written: every episode has t, x (T x n), u (T x m) of matching
/// sizes, finite values, distinct non-negative ids and valid times (check_times). Throws
/// std::invalid_argument naming the episode and sample otherwise, so that writers never produce a
/// file that the readers would reject.
void check_writable(const MeasurementSet& set);

/// Why `names` cannot be the estimated states of a set of `system` (a name that is not one of its
/// states, or one listed twice), as "<problem>; expected <...>"; nullopt when they can.
std::optional<std::string> estimated_states_problem(const std::vector<std::string>& names,
                                                    const SystemSignature& system);

}  // namespace gpilqg::measurements_detail
