/// CSV measurement files (docs/formats.md#measurement-data-csv-and-hdf5): a strict reader that names
/// the offending line of any bad input, and a writer whose numbers read back bit for bit.
///
/// A header without the leading `episode` column is a file of one episode (id 0), so a continuous
/// record needs no column of zeros.
///
/// Accepted beyond the plain contract, because they carry no meaning: "\r\n" line endings, a UTF-8
/// byte-order mark before the header, a missing final newline, and blank lines at the very end of
/// the file. Rejected: a blank line anywhere else (it usually marks files pasted together), and
/// whitespace or a '+' sign around numbers (fields must be plain numbers, nothing is trimmed).

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>
#include <unordered_set>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "csv_text.hpp"
#include "measurements_internal.hpp"
#include "name_list.hpp"

namespace gpilqg {

namespace {

using measurements_detail::expected_columns;
using measurements_detail::join;

std::string line_location(long line) { return fmt::format("line {}", line); }

/// The field as it appears in the file, quoted and shortened for an error message.
std::string quote_field(std::string_view field) { return name_list::quoted(field); }

/// The whole file, after check_input_file (a regular file of at most kMaxDataFileBytes).
std::string read_whole_file(const std::filesystem::path& file) {
  check_input_file(file, kMaxDataFileBytes, "a measurement file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw DataError(file, "", "cannot open the file for reading", "a readable measurement file");
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) throw DataError(file, "", "reading the file failed", "a readable measurement file");
  return std::move(contents).str();
}

bool is_blank(std::string_view line) { return line.find_first_not_of(" \t") == std::string_view::npos; }

using csv_text::split_fields;
using csv_text::split_lines;

/// Reads the rows of one file into episodes, checking each row as it comes so that the first
/// problem in file order is the one reported.
class CsvReader {
 public:
  CsvReader(const std::filesystem::path& file, const SystemSignature& system)
      : file_(file),
        system_(system),
        columns_(expected_columns(system)),
        n_(system.states.size()),
        m_(system.controls.size()) {}

  MeasurementSet read(std::string_view text) {
    std::string_view view = text;
    constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
    if (view.substr(0, kByteOrderMark.size()) == kByteOrderMark) view.remove_prefix(kByteOrderMark.size());
    const std::vector<std::string_view> lines = split_lines(view);

    std::size_t last = lines.size();  // one past the last non-blank line
    while (last > 0 && is_blank(lines[last - 1])) --last;
    if (last == 0)
      throw DataError(file_, line_location(1), "the file is empty",
                      "a header line '" + join(columns_, ",") + "' followed by data rows");
    for (std::size_t i = 0; i < last; ++i)
      if (is_blank(lines[i]))
        throw DataError(file_, line_location(static_cast<long>(i) + 1), "blank line",
                        i == 0
                            ? "the header line '" + join(columns_, ",") + "'"
                            : std::string("a data row (blank lines are allowed only at the end of the file)"));

    episode_column_ = check_header(lines[0]);
    if (last == 1)
      throw DataError(file_, line_location(2), "no data rows after the header",
                      "one row per time step, at least 2 rows per episode");
    for (std::size_t i = 1; i < last; ++i) read_row(lines[i], static_cast<long>(i) + 1);
    finish_episode();

    MeasurementSet set;
    set.system = system_;
    set.episodes = std::move(episodes_);
    return set;
  }

 private:
  /// Compares the header with the expected columns in time linear in its width (hash sets), and
  /// names at most name_list::kMaxListedNames columns of each kind, so that a header of any width
  /// gives a short message.
  /// Returns whether the header has the `episode` column; without it the file is one episode, id 0
  /// (a continuous record).
  bool check_header(std::string_view line) const {
    const std::vector<std::string_view> found = split_fields(line);
    if (std::equal(found.begin(), found.end(), columns_.begin(), columns_.end())) return true;
    if (std::equal(found.begin(), found.end(), columns_.begin() + 1, columns_.end())) return false;
    const std::unordered_set<std::string_view> known(columns_.begin(), columns_.end());
    std::unordered_set<std::string_view> seen, reported;
    std::vector<std::string> unknown, repeated, missing;
    for (const std::string_view name : found) {
      const bool first = seen.insert(name).second;
      if (!known.contains(name)) {
        if (first) unknown.emplace_back(name);
      } else if (!first && reported.insert(name).second) {
        repeated.emplace_back(name);
      }
    }
    for (const std::string& name : columns_)
      if (!seen.contains(name)) missing.push_back(name);
    const std::string expected = join(columns_, ",");
    if (missing.empty() && unknown.empty() && repeated.empty())  // the same names (as many): another order
      throw DataError(file_, line_location(1),
                      "the header has the right column names for system '" + system_.name +
                          "' but in a different order: found " + std::string(line),
                      "the order " + expected + " (episode, t, the states in order, the controls in order)");
    std::string problem = "the header columns do not match system '" + system_.name + "':";
    if (!missing.empty()) problem += " missing " + name_list::quoted_list(missing) + ";";
    if (!unknown.empty()) problem += " unknown " + name_list::quoted_list(unknown) + ";";
    if (!repeated.empty()) problem += " repeated " + name_list::quoted_list(repeated) + ";";
    problem += found.size() > name_list::kMaxListedNames ? fmt::format(" found {} columns: ", found.size()) : " found ";
    problem += name_list::plain_list(found, ",");
    throw DataError(file_, line_location(1), problem, "the columns " + expected);
  }

  long parse_episode(std::string_view field, long line) const {
    long value = -1;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
    if (error != std::errc() || end != field.data() + field.size() || value < 0)
      throw DataError(file_, line_location(line),
                      "column 'episode': " + quote_field(field) + " is not a non-negative integer",
                      "an episode number 0, 1, 2, ...");
    return value;
  }

  double parse_number(std::string_view field, const std::string& column, long line) const {
    double value = 0.0;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
    if (error == std::errc::result_out_of_range)
      throw DataError(file_, line_location(line),
                      "column '" + column + "': " + quote_field(field) + " is out of the range of a double",
                      "a finite number");
    if (error != std::errc() || end != field.data() + field.size())
      throw DataError(file_, line_location(line),
                      "column '" + column + "': cannot read " + quote_field(field) + " as a number",
                      "a plain decimal number such as -0.25 or 1.5e-3 (no spaces or other characters)");
    if (!std::isfinite(value))
      throw DataError(file_, line_location(line),
                      "column '" + column + "': " + quote_field(field) + " is not a finite number",
                      "a finite number (no nan or inf)");
    return value;
  }

  void read_row(std::string_view text, long line) {
    const std::vector<std::string_view> fields = split_fields(text);
    // Field j is column j + skipped of columns_ (skipped = 1 without the episode column).
    const std::size_t skipped = episode_column_ ? 0 : 1;
    if (fields.size() != columns_.size() - skipped) {
      const std::vector<std::string> header(columns_.begin() + static_cast<std::ptrdiff_t>(skipped), columns_.end());
      throw DataError(file_, line_location(line), fmt::format("the row has {} fields", fields.size()),
                      fmt::format("{} fields ({})", header.size(), join(header, ",")));
    }
    const long id = episode_column_ ? parse_episode(fields[0], line) : 0;
    const std::size_t first_value = episode_column_ ? 1 : 0;
    std::vector<double> values(fields.size() - first_value);
    for (std::size_t j = first_value; j < fields.size(); ++j)
      values[j - first_value] = parse_number(fields[j], columns_[j + skipped], line);

    if (!started_ || id != current_id_) start_episode(id, line);
    const double t = values[0];
    if (!times_.empty()) {
      const double first_step = times_.size() == 1 ? t - times_[0] : times_[1] - times_[0];
      if (const auto issue = measurements_detail::check_step(times_.back(), t, first_step))
        throw DataError(file_, line_location(line), fmt::format("episode {}: {}", id, issue->problem),
                        issue->expected);
    }
    times_.push_back(t);
    states_.insert(states_.end(), values.begin() + 1, values.begin() + 1 + static_cast<long>(n_));
    controls_.insert(controls_.end(), values.begin() + 1 + static_cast<long>(n_), values.end());
  }

  void start_episode(long id, long line) {
    if (const auto seen = first_lines_.find(id); seen != first_lines_.end())
      throw DataError(file_, line_location(line),
                      fmt::format("episode {} resumes after episode {} started at line {} (episode {} began at "
                                  "line {})",
                                  id, current_id_, current_first_line_, id, seen->second),
                      "all rows of an episode to be contiguous");
    if (started_) finish_episode();
    started_ = true;
    current_id_ = id;
    current_first_line_ = line;
    first_lines_.emplace(id, line);
  }

  /// Moves the rows gathered so far into a new Episode (needs 2 rows or more).
  void finish_episode() {
    const auto T = static_cast<Eigen::Index>(times_.size());
    if (T < 2) {
      const auto issue = measurements_detail::too_few_samples(T);
      throw DataError(file_, line_location(current_first_line_),
                      fmt::format("episode {} {}", current_id_, issue.problem), issue.expected);
    }
    Episode episode;
    episode.id = current_id_;
    episode.t = Eigen::Map<const Vector>(times_.data(), T);
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    episode.x = Eigen::Map<const RowMajor>(states_.data(), T, static_cast<Eigen::Index>(n_));
    episode.u = Eigen::Map<const RowMajor>(controls_.data(), T, static_cast<Eigen::Index>(m_));
    episodes_.push_back(std::move(episode));
    times_.clear();
    states_.clear();
    controls_.clear();
  }

  const std::filesystem::path& file_;
  const SystemSignature& system_;
  const std::vector<std::string> columns_;
  const std::size_t n_, m_;

  bool episode_column_ = true;  // false: the header has no `episode` column, every row is episode 0
  std::vector<Episode> episodes_;
  std::map<long, long> first_lines_;  // episode id -> line of its first row
  bool started_ = false;
  long current_id_ = -1;
  long current_first_line_ = 0;
  std::vector<double> times_, states_, controls_;  // rows of the current episode, row-major
};

}  // namespace

MeasurementSet read_measurements_csv(const std::filesystem::path& file, const SystemSignature& system) {
  return CsvReader(file, system).read(read_whole_file(file));
}

MeasurementSet parse_measurements_csv(std::string_view text, const std::filesystem::path& file,
                                      const SystemSignature& system) {
  return CsvReader(file, system).read(text);
}

void write_measurements_csv(const std::filesystem::path& file, const MeasurementSet& set) {
  measurements_detail::check_writable(set);
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "{}\n", join(expected_columns(set.system), ","));
  for (const Episode& e : set.episodes) {
    for (Eigen::Index i = 0; i < e.length(); ++i) {
      fmt::format_to(std::back_inserter(out), "{},{}", e.id, e.t(i));
      for (Eigen::Index j = 0; j < e.x.cols(); ++j) fmt::format_to(std::back_inserter(out), ",{}", e.x(i, j));
      for (Eigen::Index j = 0; j < e.u.cols(); ++j) fmt::format_to(std::back_inserter(out), ",{}", e.u(i, j));
      out.push_back('\n');
    }
  }
  write_file_atomically(file, std::string_view(out.data(), out.size()));
}

}  // namespace gpilqg
