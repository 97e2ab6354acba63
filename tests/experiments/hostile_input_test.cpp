/// Every reader of the command line against hostile inputs (a FIFO, /dev/zero, a directory, a loop of
/// symbolic links, a missing file, an oversized sparse file): each is refused promptly, before it is
/// opened, with an InputError whose message starts with the path (input_file.hpp). The measurement
/// and HDF5 readers of core have the same table in tests/core/hostile_input_test.cpp.

#include <gtest/gtest.h>

#include "gpilqg/core/input_file.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/import_map.hpp"
#include "gpilqg/experiments/plan_config.hpp"
#include "gpilqg/experiments/policy_file.hpp"
#include "gpilqg/experiments/profile.hpp"
#include "gpilqg/experiments/run_config.hpp"
#include "gpilqg/experiments/solve_config.hpp"
#include "hostile_inputs.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

TEST(HostileInputs, EveryCommandLineReaderRefusesThemWithInputError) {
  const std::vector<test::Reader> readers = {
      {"read_solve_config", ".toml", kMaxConfigFileBytes, [](const fs::path& f) { read_solve_config(f); }},
      {"read_plan_config", ".toml", kMaxConfigFileBytes, [](const fs::path& f) { read_plan_config(f); }},
      {"load_run_config", ".toml", kMaxConfigFileBytes, [](const fs::path& f) { load_run_config("cartpole", f); }},
      {"read_import_map", ".toml", kMaxConfigFileBytes, [](const fs::path& f) { read_import_map(f); }},
      {"diagnosis::read_model_file", ".toml", kMaxConfigFileBytes,
       [](const fs::path& f) { diagnosis::read_model_file(f, "cartpole"); }},
      {"read_policy_file", ".h5", kMaxDataFileBytes, [](const fs::path& f) { read_policy_file(f); }},
      {"read_profile_data (HDF5)", ".h5", kMaxDataFileBytes, [](const fs::path& f) { read_profile_data(f, {}); }},
      {"read_profile_data (CSV)", ".csv", kMaxDataFileBytes,
       [](const fs::path& f) {
         ProfileDataOptions options;
         options.system = "cartpole";
         read_profile_data(f, options);
       }},
  };
  test::expect_readers_refuse_hostile_inputs<InputError>(readers, test::temporary_dir("hostile"));
}

TEST(HostileInputsCli, TheCommandLineExitsTwoOnAFifo) {
  const fs::path dir = test::temporary_dir("hostile");
  const auto inputs = test::make_hostile_inputs(dir, ".csv", kMaxDataFileBytes);
  const fs::path fifo = inputs.front().path;
  ASSERT_EQ(inputs.front().name, "fifo");
  const auto result = test::run_cli("data info '" + fifo.string() + "' --system cartpole");
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_EQ(result.err, "error: " + fifo.string() +
                            ": is a FIFO (named pipe), not a regular file; expected a measurement file\n");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gpilqg
