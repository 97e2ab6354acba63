/// The `gpilqg` program end to end (docs/command-line.md): help, `data info` as text and JSON, and
/// the exit-status contract (2 with "error:" naming the file and line on bad input).

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

const std::string kValidCsv =
    "episode,t,x,x_dot,theta,theta_dot,force\n"
    "0,0,0.01,0.09,-0.18,-0.59,-11.2\n"
    "0,0.05,0.02,0.1,-0.2,-0.6,-11\n"
    "0,0.1,0.03,0.11,-0.22,-0.61,-10.5\n"
    "1,0,1,2,3,4,5\n"
    "1,0.05,1,2,3,4,5\n";

fs::path write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  return file;
}

using test::quote;

TEST(Cli, HelpListsTheDataCommand) {
  const auto result = test::run_cli("--help");
  EXPECT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("data"), std::string::npos) << result.out;
  const auto info_help = test::run_cli("data info --help");
  EXPECT_EQ(info_help.status, 0) << info_help.err;
  EXPECT_NE(info_help.out.find("--system"), std::string::npos) << info_help.out;
  EXPECT_NE(info_help.out.find("--json"), std::string::npos) << info_help.out;
}

TEST(Cli, VersionNamesTheBlasLibraryItLoaded) {
  const auto result = test::run_cli("--version");
  EXPECT_EQ(result.status, 0) << result.err;
  EXPECT_EQ(result.out.rfind("gpilqg ", 0), 0u) << result.out;
  // The file the loader resolved for BLAS's dgemm: a libblas or an OpenBLAS library, never unknown.
  const auto blas = result.out.find("BLAS: /");
  ASSERT_NE(blas, std::string::npos) << result.out;
  EXPECT_TRUE(result.out.find("blas", blas + 7) != std::string::npos) << result.out;
}

TEST(Cli, RunsOpenBlasOnKernelsThisProcessorCanUse) {
  // OpenBLAS 0.3.21 falls back to its SSE3 ("Prescott") kernels on processors it does not know; the
  // program then starts itself again with OPENBLAS_CORETYPE set (gp/blas_library.hpp).
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) GTEST_SKIP() << "OPENBLAS_CORETYPE is set by the caller";
  const auto result = test::run_cli("--version");
  ASSERT_EQ(result.status, 0) << result.err;
  const auto core = result.out.find(", core ");
  if (core == std::string::npos) GTEST_SKIP() << "not OpenBLAS: " << result.out;
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (!(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))) GTEST_SKIP() << "no AVX2 here";
  const std::string name = result.out.substr(core + 7, result.out.find(')', core) - core - 7);
  bool wide = false;
  for (const char* w : {"Haswell", "Zen", "SkylakeX", "Cooperlake", "SapphireRapids", "Excavator"}) wide = wide || name == w;
  EXPECT_TRUE(wide) << "OpenBLAS runs its '" << name << "' kernels on a processor with AVX2:\n" << result.out;
#else
  GTEST_SKIP() << "x86-64 only";
#endif
}

TEST(Cli, DataInfoPrintsASummaryTable) {
  const auto file = write_text(test::temporary_dir("cli_data") / "cart.csv", kValidCsv);
  const auto result = test::run_cli("data info " + quote(file) + " --system cartpole");
  EXPECT_EQ(result.status, 0) << result.err;
  EXPECT_EQ(result.err, "");
  for (const char* part : {"cartpole", "episodes  2", "samples   5", "dt        0.05 s", "theta_dot", "force"})
    EXPECT_NE(result.out.find(part), std::string::npos) << "'" << part << "' not in:\n" << result.out;
}

TEST(Cli, DataInfoJsonIsOneDocumentOnStdout) {
  const auto file = write_text(test::temporary_dir("cli_data") / "cart.csv", kValidCsv);
  const auto result = test::run_cli("data info " + quote(file) + " --system cartpole --json");
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_EQ(result.err, "");
  nlohmann::json j;
  ASSERT_NO_THROW(j = nlohmann::json::parse(result.out)) << result.out;
  EXPECT_EQ(j.at("file"), file.string());
  EXPECT_EQ(j.at("system"), "cartpole");
  EXPECT_EQ(j.at("episodes"), 2);
  EXPECT_EQ(j.at("samples"), 5);
  EXPECT_NEAR(j.at("dt").get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(j.at("duration_s").get<double>(), 0.15, 1e-12);
  ASSERT_EQ(j.at("states").size(), 4u);
  EXPECT_EQ(j.at("states").at(1).at("name"), "x_dot");
  EXPECT_EQ(j.at("states").at(1).at("unit"), "m/s");
  EXPECT_EQ(j.at("controls").at(0).at("name"), "force");
  EXPECT_EQ(j.at("controls").at(0).at("min"), -11.2);
  EXPECT_EQ(j.at("controls").at(0).at("max"), 5.0);
}

TEST(Cli, DataInfoReadsHdf5) {
  const auto dir = test::temporary_dir("cli_data");
  // Produce the HDF5 file with the library's own writer, from the CSV.
  const auto csv = write_text(dir / "cart.csv", kValidCsv);
  const auto set = read_measurements(csv, system_signature("cartpole"));
  write_measurements(dir / "cart.h5", set);
  const auto result = test::run_cli("data info " + quote(dir / "cart.h5") + " --system cartpole --json");
  ASSERT_EQ(result.status, 0) << result.err;
  const auto j = nlohmann::json::parse(result.out);
  EXPECT_EQ(j.at("samples"), 5);
}

TEST(Cli, BadFileExitsWithTwoNamingTheFileAndLine) {
  const auto file = write_text(test::temporary_dir("cli_data") / "broken.csv",
                               "episode,t,x,x_dot,theta,theta_dot,force\n0,0,1,2,3,4,5\n0,0.1,1,2,nan,4,5\n");
  for (const char* json : {"", " --json"}) {
    const auto result = test::run_cli("data info " + quote(file) + " --system cartpole" + json);
    EXPECT_EQ(result.status, 2);
    EXPECT_EQ(result.out, "") << "nothing on stdout on failure";
    EXPECT_EQ(result.err.rfind("error: ", 0), 0u) << result.err;
    EXPECT_NE(result.err.find(file.string() + ":line 3: column 'theta'"), std::string::npos) << result.err;
  }
}

TEST(Cli, MissingFileExitsWithTwo) {
  const auto file = test::temporary_dir("cli_data") / "absent.csv";
  const auto result = test::run_cli("data info " + quote(file) + " --system cartpole");
  EXPECT_EQ(result.status, 2);
  EXPECT_EQ(result.err.rfind("error: ", 0), 0u) << result.err;
  EXPECT_NE(result.err.find("absent.csv"), std::string::npos) << result.err;
}

TEST(Cli, UnknownSystemExitsWithTwoListingTheChoices) {
  const auto file = write_text(test::temporary_dir("cli_data") / "cart.csv", kValidCsv);
  const auto result = test::run_cli("data info " + quote(file) + " --system bicycle");
  EXPECT_EQ(result.status, 2);
  EXPECT_EQ(result.err.rfind("error: ", 0), 0u) << result.err;
  EXPECT_NE(result.err.find("bicycle"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("cartpole"), std::string::npos) << result.err;
}

TEST(Cli, UsageErrorsExitWithTwo) {
  const auto file = write_text(test::temporary_dir("cli_data") / "cart.csv", kValidCsv);
  for (const std::string& arguments :
       {"data info " + quote(file), std::string("data"), std::string("data info")}) {
    const auto result = test::run_cli(arguments);
    EXPECT_EQ(result.status, 2) << arguments;
    EXPECT_EQ(result.err.rfind("error:", 0), 0u) << arguments << ": " << result.err;
  }
}

}  // namespace
}  // namespace gpilqg
