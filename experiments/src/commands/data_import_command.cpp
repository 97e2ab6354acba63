/// `gpilqg data import LOG --system NAME --map MAP.toml --out FILE [--json]`: a robot's log (CSV, MAT
/// or HDF5) into the measurement format of docs/formats.md#measurement-data-csv-and-hdf5, by the map of
/// docs/data-import.md. Bad maps and logs exit 2 with the file and the line, field, column or dataset
/// at fault.

#include "data_import_command.hpp"
#include "output_options.hpp"

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "gpilqg/core/log_import.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/raw_log.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/import_map.hpp"
#include "gpilqg/experiments/import_report.hpp"

namespace gpilqg::cli {

namespace {

struct DataImportOptions {
  std::string log;
  std::string system;
  std::string map;
  std::string out;
  bool json = false;
};

/// Reads the map first (its errors need no log), then the log; writes the set (by extension, .h5 /
/// .hdf5 or .csv) and prints the report.
int run_data_import(const DataImportOptions& options) {
  check_output_file_option("--out", options.out, {"data import writes a measurement file (CSV or HDF5)", kMeasurementExtensions},
                           {{"LOG", options.log}, {"--map", options.map}, system_input(options.system)});
  const SystemSignature signature = system_signature(options.system);
  const LogMap map = read_import_map(options.map);
  const RawLog log = read_raw_log(options.log);
  const ImportResult result = import_log(log, map, signature);
  write_measurements(options.out, result.set);
  if (options.json)
    std::cout << import_report_json(result.report, options.out).dump(2) << '\n';
  else
    std::cout << format_import_report(result.report, options.out);
  return kExitSuccess;
}

}  // namespace

void add_data_import_command(CLI::App& data, CommandAction& action) {
  CLI::App* import = data.add_subcommand(
      "import",
      "Turn a robot's log (CSV, MAT or HDF5) into a measurement file: map columns and units, resample "
      "to a fixed dt, split at gaps, estimate missing velocities (docs/data-import.md)");
  auto options = std::make_shared<DataImportOptions>();
  import->add_option("LOG", options->log, "The log: .csv, .mat, or .h5 / .hdf5")->required();
  import->add_option("--system", options->system, kSystemHelp)->required();
  import->add_option("--map", options->map, "TOML map of columns, units, resampling and velocity estimation")
      ->type_name("MAP.toml")
      ->required();
  import->add_option("--out", options->out, "Measurement file to write: .h5 / .hdf5 or .csv")->type_name("FILE")->required();
  import->add_flag("--json", options->json, "Print the report as one JSON document on stdout");
  import->callback([options, &action] { action = [options] { return run_data_import(*options); }; });
}

}  // namespace gpilqg::cli
