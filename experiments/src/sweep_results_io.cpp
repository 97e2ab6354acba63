#include "gpilqg/experiments/sweep_results_io.hpp"

#include <fmt/format.h>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/utc_time.hpp"
#include "gpilqg/core/version.hpp"
#include "gpilqg/experiments/run_results_io.hpp"

namespace gpilqg {

void write_sweep_results(const std::filesystem::path& file, const SweepConfig& sweep, const std::vector<RunResults>& results) {
  if (results.size() != sweep.points.size()) throw std::logic_error("write_sweep_results: one result per grid point is needed");
  write_atomically(file, [&](const std::filesystem::path& temporary) {
    Hdf5Writer h5(temporary);
    h5.attribute("/", "schema_version", std::int64_t{1});
    h5.attribute("/", "gpilqg_version", std::string(kVersionString));
    h5.attribute("/", "created", utc_timestamp());
    h5.attribute("/", "system", sweep.system);
    h5.attribute("/", "sweep", sweep.text);
    h5.attribute("/", "grid_fields", sweep.fields);
    h5.attribute("/", "points", static_cast<std::int64_t>(sweep.points.size()));
    for (std::size_t p = 0; p < results.size(); ++p) {
      const std::string group = fmt::format("/point_{}", p);
      write_run_results_to(h5, group, results[p]);
      std::vector<std::string> values;
      for (const auto& [field, value] : sweep.points[p].values) values.push_back(value);
      h5.attribute(group, "grid_values", values);
      h5.attribute(group, "label", sweep.points[p].label());
    }
    h5.close();
  });
}

}  // namespace gpilqg
