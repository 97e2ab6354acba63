/// Measurement sets: the parts shared by both file formats (errors, dispatch by extension, the
/// checks of one episode, safe writing through a temporary file) and summarize().

#include "gpilqg/core/measurements.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <tuple>
#include <utility>
#include <stdexcept>

#include "gpilqg/core/atomic_file.hpp"
#include "measurements_internal.hpp"
#include "name_list.hpp"

namespace gpilqg {

double Episode::dt() const {
  const Eigen::Index T = t.size();
  if (T < 2) return 0.0;
  const double steps = static_cast<double>(T - 1);
  const double dt = (t(T - 1) - t(0)) / steps;
  // Times near the largest double (e.g. -1e308 to 1e308) span more than a double holds while their
  // step does not: divided first, the step is finite whenever it is representable.
  return std::isfinite(dt) ? dt : t(T - 1) / steps - t(0) / steps;
}

std::optional<std::string> column_name_problem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name.find(',') != std::string_view::npos) return "contains a comma, which separates CSV fields";
  if (name.find_first_of("\r\n") != std::string_view::npos) return "contains a line break, which ends a CSV row";
  if (name == "episode" || name == "t") return fmt::format("is '{}', a fixed column of measurement files", name);
  return std::nullopt;
}

long MeasurementSet::sample_count() const {
  long count = 0;
  for (const Episode& episode : episodes) count += episode.length();
  return count;
}

namespace {

std::string data_error_message(const std::filesystem::path& file, const std::string& location,
                               const std::string& problem) {
  if (location.empty()) return file.string() + ": " + problem;
  return file.string() + ":" + location + ": " + problem;
}

/// The extension in lower case, e.g. ".csv".
std::string lower_extension(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

enum class Format { Csv, Hdf5 };

Format format_of(const std::filesystem::path& file) {
  const std::string extension = lower_extension(file);
  if (extension == ".csv") return Format::Csv;
  if (extension == ".h5" || extension == ".hdf5") return Format::Hdf5;
  throw DataError(file, "", "unknown measurement file extension '" + file.extension().string() + "'",
                  "'.csv', '.h5' or '.hdf5'");
}

}  // namespace

DataError::DataError(const std::filesystem::path& file, const std::string& location, const std::string& problem)
    : std::runtime_error(data_error_message(file, location, problem)), file_(file), location_(location) {}

DataError::DataError(const std::filesystem::path& file, const std::string& location, const std::string& problem,
                     const std::string& expected)
    : DataError(file, location, problem + "; expected " + expected) {}

MeasurementSet read_measurements(const std::filesystem::path& file, const SystemSignature& system) {
  return format_of(file) == Format::Csv ? read_measurements_csv(file, system)
                                        : read_measurements_hdf5(file, system);
}

void write_measurements(const std::filesystem::path& file, const MeasurementSet& set) {
  if (format_of(file) == Format::Csv)
    write_measurements_csv(file, set);
  else
    write_measurements_hdf5(file, set);
}

namespace measurements_detail {

std::optional<SampleIssue> check_step(double previous, double current, double first_step) {
  const double found = current - previous;
  if (!(found > 0.0))
    return SampleIssue{0, fmt::format("t = {} is not greater than the previous t = {}", current, previous),
                       "t strictly increasing within an episode"};
  if (std::abs(found - first_step) > kDtRelativeTolerance * first_step)
    return SampleIssue{0,
                       fmt::format("dt = {} (t = {} after t = {}) differs from the episode's first dt = {}",
                                   found, current, previous, first_step),
                       fmt::format("dt = {} (constant within an episode to relative tolerance {})", first_step,
                                   kDtRelativeTolerance)};
  return std::nullopt;
}

SampleIssue too_few_samples(Eigen::Index count) {
  return SampleIssue{
      0, fmt::format("has {} sample{}; need at least 2 to define dt", count, count == 1 ? "" : "s"),
      "2 or more samples per episode"};
}

std::optional<SampleIssue> check_times(const Vector& t) {
  const Eigen::Index T = t.size();
  if (T < 2) {
    SampleIssue issue = too_few_samples(T);
    issue.problem = "the episode " + issue.problem;
    return issue;
  }
  for (Eigen::Index i = 1; i < T; ++i) {
    if (auto issue = check_step(t(i - 1), t(i), t(1) - t(0))) {
      issue->index = i;
      return issue;
    }
  }
  return std::nullopt;
}

std::vector<std::string> expected_columns(const SystemSignature& system) {
  std::vector<std::string> columns{"episode", "t"};
  for (const Quantity& q : system.states) columns.push_back(q.name);
  for (const Quantity& q : system.controls) columns.push_back(q.name);
  return columns;
}

std::string join(const std::vector<std::string>& names, const std::string& separator) {
  std::string joined;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) joined += separator;
    joined += names[i];
  }
  return joined;
}

std::string format_number(double value) { return fmt::format("{}", value); }

namespace {

void check_finite(const MatrixCRef& values, long id, const char* what) {
  for (Eigen::Index i = 0; i < values.rows(); ++i)
    for (Eigen::Index j = 0; j < values.cols(); ++j)
      if (!std::isfinite(values(i, j)))
        throw std::invalid_argument(fmt::format("measurement set: episode {}: {}({}, {}) = {} is not finite",
                                                id, what, i, j, values(i, j)));
}

}  // namespace

void check_writable(const MeasurementSet& set) {
  const auto n = static_cast<Eigen::Index>(set.system.states.size());
  const auto m = static_cast<Eigen::Index>(set.system.controls.size());
  std::set<long> ids;
  for (const Episode& e : set.episodes) {
    if (e.id < 0) throw std::invalid_argument(fmt::format("measurement set: episode id {} is negative", e.id));
    if (!ids.insert(e.id).second)
      throw std::invalid_argument(fmt::format("measurement set: episode id {} appears twice", e.id));
    const Eigen::Index T = e.t.size();
    if (e.x.rows() != T || e.x.cols() != n || e.u.rows() != T || e.u.cols() != m)
      throw std::invalid_argument(fmt::format(
          "measurement set: episode {}: x is {} x {} and u is {} x {}; expected {} x {} and {} x {} "
          "(T = length of t, {} states, {} controls)",
          e.id, e.x.rows(), e.x.cols(), e.u.rows(), e.u.cols(), T, n, T, m, n, m));
    check_finite(e.t, e.id, "t");
    check_finite(e.x, e.id, "x");
    check_finite(e.u, e.id, "u");
    if (const auto issue = check_times(e.t))
      throw std::invalid_argument(fmt::format("measurement set: episode {}, sample {}: {}; expected {}", e.id,
                                              issue->index, issue->problem, issue->expected));
  }
  if (const auto problem = estimated_states_problem(set.estimated_states, set.system))
    throw std::invalid_argument("measurement set: estimated_states: " + *problem);
}

std::optional<std::string> estimated_states_problem(const std::vector<std::string>& names,
                                                    const SystemSignature& system) {
  std::set<std::string> seen;
  for (const std::string& name : names) {
    if (index_of(system.states, name) < 0)
      return fmt::format("{} is not a state of system '{}'; expected some of its states: {}", name_list::quoted(name),
                         system.name, join(names_of(system.states)));
    if (!seen.insert(name).second)
      return fmt::format("{} is listed twice; expected each state at most once", name_list::quoted(name));
  }
  return std::nullopt;
}

}  // namespace measurements_detail

namespace {

/// Accumulates one column over all samples: min, max, mean, and the population standard deviation
/// (computed from deviations about the mean in a second pass, for accuracy). Values near the largest
/// double (1e308) overflow the plain sum or the squared deviations; the statistics are then taken
/// of the values divided by the largest magnitude s = max(|min|, |max|) and scaled back, which is
/// exact in range: |mean| <= s and std <= (max - min) / 2 <= s are finite whenever the values are.
ColumnSummary summarize_column(const Quantity& quantity, const std::vector<Episode>& episodes,
                               Eigen::Index column, bool is_state) {
  ColumnSummary s{quantity.name, quantity.unit};
  long count = 0;
  for (const Episode& e : episodes) {
    const auto values = is_state ? e.x.col(column) : e.u.col(column);
    if (values.size() == 0) continue;
    const double lo = values.minCoeff(), hi = values.maxCoeff();
    s.min = count == 0 ? lo : std::min(s.min, lo);
    s.max = count == 0 ? hi : std::max(s.max, hi);
    count += values.size();
  }
  if (count == 0) return s;
  const auto moments = [&](double scale) {
    double sum = 0.0;
    for (const Episode& e : episodes) sum += ((is_state ? e.x.col(column) : e.u.col(column)).array() / scale).sum();
    const double mean = sum / static_cast<double>(count);
    double squares = 0.0;
    for (const Episode& e : episodes)
      squares += ((is_state ? e.x.col(column) : e.u.col(column)).array() / scale - mean).square().sum();
    return std::pair{mean * scale, std::sqrt(squares / static_cast<double>(count)) * scale};
  };
  std::tie(s.mean, s.std) = moments(1.0);
  const double scale = std::max(std::abs(s.min), std::abs(s.max));
  if (!(std::isfinite(s.mean) && std::isfinite(s.std)) && scale > 0.0) std::tie(s.mean, s.std) = moments(scale);
  return s;
}

}  // namespace

MeasurementSummary summarize(const MeasurementSet& set) {
  MeasurementSummary summary;
  summary.system = set.system.name;
  summary.estimated_states = set.estimated_states;
  summary.episodes = static_cast<int>(set.episodes.size());
  summary.samples = set.sample_count();
  bool first = true;
  long double duration = 0.0L;  // a span of times near +-1e308 exceeds a double; its sum is kept exact in range
  for (const Episode& e : set.episodes) {
    if (e.length() < 2) continue;
    const double dt = e.dt();
    summary.dt_min = first ? dt : std::min(summary.dt_min, dt);
    summary.dt_max = first ? dt : std::max(summary.dt_max, dt);
    duration += static_cast<long double>(e.t(e.length() - 1)) - static_cast<long double>(e.t(0));
    first = false;
  }
  summary.duration = static_cast<double>(duration);
  for (std::size_t j = 0; j < set.system.states.size(); ++j)
    summary.states.push_back(
        summarize_column(set.system.states[j], set.episodes, static_cast<Eigen::Index>(j), true));
  for (std::size_t j = 0; j < set.system.controls.size(); ++j)
    summary.controls.push_back(
        summarize_column(set.system.controls[j], set.episodes, static_cast<Eigen::Index>(j), false));
  return summary;
}

void check_measurement_set(const MeasurementSet& set) { measurements_detail::check_writable(set); }

}  // namespace gpilqg
