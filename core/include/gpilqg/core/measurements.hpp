#pragma once
/// @file measurements.hpp
/// Measurement data sets (docs/formats.md#measurement-data-csv-and-hdf5, a fixed contract): episodes of
/// measured states and applied controls at a constant step, read from and written to CSV and HDF5 with
/// full validation.
///
/// CSV: header `episode,t,<state names>,<control names>`, one row per time step. A row holds the
/// state measured at time t and the control applied from t until the next row of the same episode.
/// A file of one episode may leave the `episode` column out (header `t,<states>,<controls>`): its
/// rows are episode 0.
/// HDF5: /episodes/<k>/t (T), /episodes/<k>/x (T x n), /episodes/<k>/u (T x m), root attributes
/// `system`, `state_names`, `control_names`, and optionally `estimated_states` (the provenance of the
/// states: MeasurementSet::estimated_states). CSV cannot carry the provenance: its states count as
/// measured.

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// One episode: T samples at a constant step.
struct Episode {
  long id = 0;  ///< the `episode` value of the CSV rows, or k of /episodes/<k>
  Vector t;     ///< T times [s], strictly increasing, constant step
  Matrix x;     ///< T x n measured states
  Matrix u;     ///< T x m applied controls
  int length() const { return static_cast<int>(t.size()); }
  /// The step, (t_last - t_first) / (T - 1); 0 for a single sample. Finite whenever the step is
  /// representable, also when the span t_last - t_first is not.
  double dt() const;
};

struct MeasurementSet {
  SystemSignature system;
  std::vector<Episode> episodes;
  /// The states that were not measured but estimated from other states, e.g. the velocities that
  /// `gpilqg data import` differentiated from positions ({"x_dot", "theta_dot"}), in the system's
  /// order; empty when every state was measured. The diagnosis chooses its criterion by it
  /// (criterion_choice.hpp): a fit that regresses on estimated states is biased (errors in
  /// variables). Stored in HDF5 as the root attribute `estimated_states`; a CSV file cannot hold it,
  /// so its states read back as measured. Every name must be a state of `system`, once.
  std::vector<std::string> estimated_states;
  /// Total number of rows over all episodes.
  long sample_count() const;
};

/// Bad input in a measurement file. what() reads "<file>:<line or dataset>: <problem>; expected
/// <what was expected>", so the user can find and fix the offending entry. `location` is e.g.
/// "line 7" (1-based, header = line 1), "/episodes/3/x" or "attribute 'system'"; it is empty only
/// when the whole file is at fault (missing, unreadable, wrong extension), and what() then reads
/// "<file>: <problem>; expected <...>".
class DataError : public std::runtime_error {
 public:
  /// `problem` already holds the "; expected ..." part.
  DataError(const std::filesystem::path& file, const std::string& location, const std::string& problem);
  /// Builds the problem text as "<problem>; expected <expected>".
  DataError(const std::filesystem::path& file, const std::string& location, const std::string& problem,
            const std::string& expected);
  const std::filesystem::path& file() const { return file_; }
  const std::string& location() const { return location_; }

 private:
  std::filesystem::path file_;
  std::string location_;
};

/// Why `name` cannot name a state or control column of a measurement file, or nullopt. CSV fields
/// are not quoted (docs/formats.md), so a name may not be empty, contain a comma or a line break
/// ("\n", "\r"), or be `episode` or `t`, the fixed columns; any other text (spaces, quotes) reads
/// back as written. A system whose names break this is refused where its names are made (a MuJoCo
/// model on loading), before any data is written.
std::optional<std::string> column_name_problem(std::string_view name);

/// Reads and validates a CSV measurement file against `system`. Throws DataError naming the line
/// (1-based, header = line 1) and the column for: a missing file, an empty file, a header whose
/// names differ from the system's (listing expected and found sets), a row with the wrong number of
/// fields, an unparsable or non-finite number, a non-integer or negative episode, an episode whose
/// rows are not contiguous, non-increasing t, dt not constant within an episode (relative tolerance
/// 1e-6), an episode with a single row (dt undefined), and a file with no data rows.
/// Accepted because they carry no meaning: "\r\n" line endings, a UTF-8 byte-order mark, a missing
/// final newline, and blank lines at the very end of the file. A blank line anywhere else is an
/// error, and fields are never trimmed (" 0.1" and "+0.1" are unparsable). Episodes keep file order.
MeasurementSet read_measurements_csv(const std::filesystem::path& file, const SystemSignature& system);

/// The same reader on CSV text already in memory (e.g. received over a pipe); `file` only names the
/// source in the DataError messages.
MeasurementSet parse_measurements_csv(std::string_view text, const std::filesystem::path& file,
                                      const SystemSignature& system);

/// Reads and validates an HDF5 measurement file: same checks, naming the dataset or attribute
/// (e.g. "/episodes/3/x", "attribute 'state_names'"), plus missing groups, datasets or attributes,
/// an optional `estimated_states` that is not a 1-D string array of distinct state names,
/// wrong shapes or types, a `system` attribute that differs from `system`, no episodes, and group
/// names under /episodes that are not non-negative integers. String attributes may be variable- or
/// fixed-length; datasets any floating-point type. Episodes come back ordered by k; other objects
/// in the file are ignored.
MeasurementSet read_measurements_hdf5(const std::filesystem::path& file, const SystemSignature& system);

/// Chooses the reader by extension (case-insensitive): .csv, or .h5 / .hdf5; any other extension
/// is a DataError. Both readers first require a readable regular file of at most kMaxDataFileBytes
/// (check_input_file, input_file.hpp: a FIFO, a device, a directory, a loop of symbolic links, a
/// missing or larger file is a DataError naming it, before anything is opened), and the HDF5 reader
/// refuses datasets that declare more values than the file can hold (dataset_size.hpp).
MeasurementSet read_measurements(const std::filesystem::path& file, const SystemSignature& system);

/// Writes CSV with every number in its shortest round-trip form, so reading it back gives the same
/// doubles bit for bit. Written atomically (atomic_file.hpp): a temporary file beside `file`, flushed
/// and renamed into place, so a failed write leaves any previous `file` untouched. Both writers first
/// check the set (shapes, finite values, distinct non-negative ids, valid times, estimated states
/// that are states) and throw std::invalid_argument rather than write a file the readers would
/// reject. The CSV header is fixed, so estimated_states is not written: the file's states read back
/// as measured (write HDF5 to keep the provenance).
void write_measurements_csv(const std::filesystem::path& file, const MeasurementSet& set);
/// Writes HDF5 in the layout above (float64, variable-length UTF-8 strings), group names /episodes/<id>,
/// and the root attribute `estimated_states` when the set has estimated states (a file without it
/// reads back as "all measured"). Written atomically like the CSV.
void write_measurements_hdf5(const std::filesystem::path& file, const MeasurementSet& set);
/// Chooses the writer by extension like read_measurements.
void write_measurements(const std::filesystem::path& file, const MeasurementSet& set);

/// Checks a set built in memory as the writers do before writing: shapes against its system, finite
/// values, distinct non-negative episode ids, times increasing at a constant step, estimated states
/// that are states of the system, each once. Throws
/// std::invalid_argument naming the episode and the sample.
void check_measurement_set(const MeasurementSet& set);

/// Range of one column over all episodes.
struct ColumnSummary {
  std::string name;
  std::string unit;
  double min = 0.0;
  double max = 0.0;
  double mean = 0.0;
  double std = 0.0;
};

struct MeasurementSummary {
  std::string system;
  int episodes = 0;
  long samples = 0;
  double dt_min = 0.0;  ///< smallest per-episode step
  double dt_max = 0.0;  ///< largest per-episode step (equal to dt_min when all episodes agree)
  double duration = 0.0;  ///< total measured time, sum over episodes of (T - 1) dt [s]
  std::vector<ColumnSummary> states;
  std::vector<ColumnSummary> controls;
  std::vector<std::string> estimated_states;  ///< MeasurementSet::estimated_states (empty: all measured)
};

/// Per-column min, max, mean and population std over all samples of all episodes, in the system's
/// order; dt_min / dt_max over the episodes' Episode::dt(); duration = sum of (t_last - t_first).
/// Statistics of a set without samples are 0. Every statistic of finite values is finite (scaled
/// accumulation), except a duration or step beyond the largest double (times spanning more than
/// 1.8e308 s), which is +inf: it is not representable, and the callers say so.
MeasurementSummary summarize(const MeasurementSet& set);

}  // namespace gpilqg
