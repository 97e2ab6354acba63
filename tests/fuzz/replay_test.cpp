/// Replays the fuzz corpora and every past finding through the fuzz harnesses (harnesses.hpp) in the
/// normal test suite, so that a fixed bug stays fixed in every build (and under ASan + UBSan in
/// build-sanitize/) without clang or libFuzzer:
///   tests/fuzz/corpus/<target>/        the seeds (small valid files and near misses)
///   tests/fuzz/regressions/<target>/   the inputs that once crashed, leaked or broke an invariant

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <vector>

#include "harnesses.hpp"

namespace gpilqg::fuzz {
namespace {

const std::filesystem::path kFuzzDir = GPILQG_FUZZ_DIR;

std::vector<std::filesystem::path> files_in(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  if (!std::filesystem::is_directory(folder)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::uint8_t> bytes_of(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Runs every file of `folder` through the harness; returns how many ran.
int replay(const Target& target, const std::filesystem::path& folder) {
  int count = 0;
  for (const auto& file : files_in(folder)) {
    const std::vector<std::uint8_t> bytes = bytes_of(file);
    try {
      target.harness(bytes.data(), bytes.size());
    } catch (const std::exception& e) {
      ADD_FAILURE() << target.name << ": " << file << ": " << e.what();
    }
    ++count;
  }
  return count;
}

class FuzzReplay : public ::testing::TestWithParam<Target> {};

TEST_P(FuzzReplay, EverySeedPassesTheHarness) {
  const Target& target = GetParam();
  EXPECT_GE(replay(target, kFuzzDir / "corpus" / std::string(target.name)), 2)
      << "expected seed files under tests/fuzz/corpus/" << target.name;
}

TEST_P(FuzzReplay, EveryPastFindingStaysFixed) {
  const Target& target = GetParam();
  replay(target, kFuzzDir / "regressions" / std::string(target.name));
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, ::testing::ValuesIn(targets()),
                         [](const ::testing::TestParamInfo<Target>& info) { return std::string(info.param.name); });

/// Valid and invalid inputs both pass the harnesses (a rejected input is not a finding).
TEST(FuzzHarness, ValidAndRejectedInputsAreNotFindings) {
  const std::string good = "episode,t,x,x_dot,theta,theta_dot,force\n0,0,0,0,0,0,1\n0,0.05,0,0,0,0,1\n";
  EXPECT_NO_THROW(fuzz_measurements_csv(reinterpret_cast<const std::uint8_t*>(good.data()), good.size()));
  const std::string bad_toml = "[system]\nname = 3\n";
  EXPECT_NO_THROW(fuzz_toml_configs(reinterpret_cast<const std::uint8_t*>(bad_toml.data()), bad_toml.size()));
}

}  // namespace
}  // namespace gpilqg::fuzz
