#pragma once
/// @file log_import.hpp
/// A robot's raw log (raw_log.hpp) into a measurement set
/// (docs/formats.md#measurement-data-csv-and-hdf5), by a map that names the log's columns for the
/// system's states and controls (docs/data-import.md):
///
/// 1. the mapped columns are scaled to SI (units.hpp); every other column is ignored and reported;
/// 2. rows are grouped by the episode column (in order of first appearance; one episode without it),
///    and time must increase strictly within each group;
/// 3. each group (a record) is split where two consecutive samples are more than max_gap apart, and
///    every such gap is listed in the report with what it made of its record;
/// 4. each piece is resampled onto t_0 + k dt (resampling.hpp): states linearly, controls held (or
///    averaged over each step when the map asks for it);
/// 5. velocities the log lacks (`<q>_dot` for a mapped `<q>`) are estimated from the resampled
///    positions by a Savitzky-Golay differentiator (savitzky_golay.hpp);
/// 6. pieces with fewer than 2 samples (or fewer than the differentiator's window) are dropped and
///    counted. Nothing else is dropped, and every count is in the report.
///
/// The map itself is read from TOML by experiments/import_map.hpp; this header holds its meaning.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/raw_log.hpp"

namespace gpilqg {

/// Where an entry of the map was written, so errors about it name the map's file, line and field.
struct MapOrigin {
  std::filesystem::path file;
  long line = 0;      ///< 1-based; 0 when unknown
  std::string field;  ///< dotted TOML path, e.g. "states.theta.column"
  /// "line 7" (or "" when the line is unknown), a DataError location.
  std::string location() const;
};

/// One target (a state, a control, the time or the episode) read from one log column.
struct ColumnMapping {
  std::string target;  ///< the system's name for it, or "time" / "episode"
  std::string column;  ///< the log's column (CSV header name, MAT variable, HDF5 dataset path)
  std::string unit;    ///< as written in the map; empty: the SI unit
  double scale = 1.0;  ///< value in SI = scale * logged value
  MapOrigin origin;    ///< of the `column` entry
  /// The pattern entry this mapping was expanded from, as written ("'q{i}' = 'pos{i}'",
  /// map_patterns.hpp); empty for an explicit entry.
  std::string pattern;
};

/// Settings of the velocity estimator for `<q>_dot` states without a column.
struct VelocityEstimator {
  /// Defaults: a quartic over 9 samples keeps the velocity's corners at control switches, where a
  /// quadratic over 7 rounded them off enough to mislead a diagnosis (docs/data-import.md).
  int window = 9;  ///< odd number of samples of the centred fit
  int order = 4;   ///< degree of the local polynomial
  MapOrigin origin;
};

struct LogMap {
  std::filesystem::path file;
  ColumnMapping time;
  std::optional<ColumnMapping> episode;
  std::optional<double> dt;       ///< resampling step [s]; default the median step of the log
  std::optional<double> max_gap;  ///< [s], a longer step starts a new episode; default 3 dt
  /// Controls on the grid: false, the hold (the control in force at tau_k); true, the step average
  /// over [tau_k, tau_k + dt) (resampling.hpp).
  bool average_controls = false;
  std::vector<ColumnMapping> states;
  std::vector<ColumnMapping> controls;
  /// Entries of [states] and [controls] whose target holds the placeholder {i} (map_patterns.hpp):
  /// `target` and `column` as written. import_log expands them over the system's names.
  std::vector<ColumnMapping> state_patterns;
  std::vector<ColumnMapping> control_patterns;
  std::optional<VelocityEstimator> velocities;
  MapOrigin states_section;    ///< where [states] is (for "state 'x' has no column")
  MapOrigin controls_section;  ///< where [controls] is
  MapOrigin resample_section;  ///< where [resample] is, or the file when it is absent
};

/// A piece of the log that was dropped, with why.
struct DroppedPiece {
  long source_episode = 0;
  double t_start = 0.0;  ///< [s], log time
  double t_end = 0.0;
  long rows = 0;
  std::string reason;
};

/// A step longer than max_gap between two samples of one record: where the record was cut.
struct SplitGap {
  long source_episode = 0;
  double t_start = 0.0;  ///< [s], log time of the last sample before the gap
  double t_end = 0.0;    ///< [s], log time of the first sample after it
  double length() const { return t_end - t_start; }
};

/// A record of the log (the rows of one episode value, or the whole log without an episode column)
/// and what max_gap made of it, so a report can say when one recording became many episodes.
struct LogRecord {
  long source_episode = 0;
  long rows = 0;
  long pieces = 1;    ///< after splitting at its gaps: 1 + the gaps in it
  long episodes = 0;  ///< pieces written; the others were dropped as too short
};

/// An episode written, and where it came from.
struct ImportedEpisode {
  long id = 0;
  long source_episode = 0;
  double t_start = 0.0;  ///< [s], log time of its first sample
  long rows = 0;         ///< log rows it was resampled from
  long samples = 0;      ///< samples written
};

/// What an import did, for the command's report (text or --json).
struct ImportReport {
  std::filesystem::path log;
  std::filesystem::path map;
  std::string format;  ///< "csv", "mat" or "hdf5"
  std::string system;
  long rows_read = 0;        ///< samples in the log
  long rows_used = 0;        ///< of them, in the episodes written
  long rows_dropped = 0;     ///< of them, in dropped pieces (rows_used + rows_dropped = rows_read)
  long samples_written = 0;  ///< resampled samples over all episodes
  double dt = 0.0;           ///< [s]
  bool dt_from_map = false;  ///< else the median step of the log
  double max_gap = 0.0;      ///< [s]
  bool max_gap_from_map = false;  ///< else 3 dt
  bool average_controls = false;  ///< controls averaged over each step, else held
  double step_min = 0.0;     ///< smallest logged step within a piece [s]
  double step_max = 0.0;     ///< largest logged step within a piece (<= max_gap) [s]
  long gaps = 0;             ///< steps longer than max_gap, each starting a new piece
  std::vector<SplitGap> gap_list;  ///< every one of them, in log order
  std::vector<LogRecord> records;  ///< the log's records in order of first appearance
  std::vector<ColumnMapping> columns;  ///< time, episode, states and controls as mapped
  std::vector<std::string> ignored_columns;  ///< log columns the map does not use
  /// The estimated velocities as {target, position column's target}, e.g. {"x_dot", "x"}.
  std::vector<std::pair<std::string, std::string>> estimated;
  std::optional<VelocityEstimator> estimator;
  double estimator_noise_gain = 0.0;      ///< sqrt(sum c^2) / dt of the centred window [1/s]
  double estimator_end_noise_gain = 0.0;  ///< the same at the first and last sample [1/s]
  double estimator_lag = 0.0;             ///< [s], zero for the centred window
  std::vector<ImportedEpisode> episodes;
  std::vector<DroppedPiece> dropped;
};

struct ImportResult {
  MeasurementSet set;
  ImportReport report;
};

/// Imports `log` by `map` for `system`, after expanding the map's patterns over the system's names
/// (map_patterns.hpp). Throws DataError naming:
/// - the map's file, line and field: a target that is not a state or control of the system, a state
///   or control without a column (and, for a velocity, no [velocities] estimator), a column the log
///   does not have (listing those it has), a column that cannot be used (text, matrix; with why);
/// - the log's file and line or variable or dataset and element: a mapped column whose length
///   differs from the time column's, a non-integer episode value, time that does not increase within
///   an episode, fewer than 2 samples, and a log with no piece long enough to keep.
ImportResult import_log(const RawLog& log, const LogMap& map, const SystemSignature& system);

}  // namespace gpilqg
