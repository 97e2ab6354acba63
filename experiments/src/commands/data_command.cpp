/// `gpilqg data info FILE --system NAME [--json]`: summarise a measurement file (CSV or HDF5,
/// docs/formats.md#measurement-data-csv-and-hdf5), or reject it with an error naming the file and the
/// line or dataset; and `gpilqg data import` (data_import_command.cpp).

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "data_import_command.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/data_info.hpp"

namespace gpilqg::cli {

namespace {

struct DataInfoOptions {
  std::string file;
  std::string system;
  bool json = false;
};

/// Reads and validates the file (DataError on bad input), then prints the summary on stdout: the
/// table, or exactly one JSON document with --json.
int run_data_info(const DataInfoOptions& options) {
  const SystemSignature signature = system_signature(options.system);
  const MeasurementSet set = read_measurements(options.file, signature);
  const MeasurementSummary summary = summarize(set);
  if (options.json)
    std::cout << data_info_json(options.file, summary).dump(2) << '\n';
  else
    std::cout << format_data_info(options.file, summary);
  return kExitSuccess;
}

}  // namespace

void add_data_command(CLI::App& app, CommandAction& action) {
  CLI::App* data = app.add_subcommand("data", "Inspect measurement files (CSV or HDF5) and import robot logs");
  data->require_subcommand(1);

  CLI::App* info = data->add_subcommand(
      "info",
      "Summarise a measurement file (episodes, samples, dt, range of every column), or reject it "
      "with the file and line or dataset at fault");
  auto options = std::make_shared<DataInfoOptions>();
  info->add_option("FILE", options->file, "Measurement file: .csv, or .h5 / .hdf5")->required();
  info->add_option("--system", options->system, kSystemHelp)->required();
  info->add_flag("--json", options->json, "Print one JSON document on stdout instead of the table");
  info->callback([options, &action] { action = [options] { return run_data_info(*options); }; });

  add_data_import_command(*data, action);
}

}  // namespace gpilqg::cli
