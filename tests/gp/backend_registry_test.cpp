/// The backend registry: every name builds the backend of that name, the settings reach it, and bad
/// names and lists are rejected with messages naming the entry and the known names.

#include "gpilqg/gp/backend_registry.hpp"

#include <gtest/gtest.h>

#include "gpilqg/gp/compact.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/ssgp.hpp"

namespace gpilqg::gp {
namespace {

TEST(BackendRegistry, EveryNameBuildsTheBackendOfThatName) {
  const auto names = backend_names();
  ASSERT_GE(names.size(), 3u);
  for (const auto& name : names) EXPECT_EQ(make_backend(name)->name(), name);
}

TEST(BackendRegistry, SettingsReachTheBackends) {
  BackendSettings settings;
  settings.exact_points = 123;
  settings.inducing = 17;
  settings.frequencies = 9;
  settings.compact_neighbours = 21;
  settings.threads = 2;
  const auto exact = make_backend("exact", settings);
  EXPECT_EQ(dynamic_cast<const ExactGpBackend&>(*exact).options().max_training_points, 123);
  const auto fitc = make_backend("fitc", settings);
  EXPECT_EQ(dynamic_cast<const FitcBackend&>(*fitc).options().inducing, 17);
  const auto ssgp = make_backend("ssgp", settings);
  EXPECT_EQ(dynamic_cast<const SsgpBackend&>(*ssgp).options().frequencies, 9);
  const auto compact = make_backend("compact", settings);
  EXPECT_EQ(dynamic_cast<const CompactBackend&>(*compact).options().initial_neighbours, 21);
  EXPECT_EQ(dynamic_cast<const CompactBackend&>(*compact).options().threads, 2);
}

TEST(BackendRegistry, UnknownNameListsTheKnownOnes) {
  try {
    make_backend("gpflow");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'gpflow'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exact, fitc, ssgp, compact"), std::string::npos) << e.what();
  }
  BackendSettings bad;
  bad.inducing = 0;
  EXPECT_THROW(make_backend("fitc", bad), std::invalid_argument);
}

TEST(BackendRegistry, ParsesListsAndRejectsBadOnes) {
  EXPECT_EQ(parse_backend_list("exact, fitc,ssgp"), (std::vector<std::string>{"exact", "fitc", "ssgp"}));
  EXPECT_EQ(parse_backend_list("ssgp"), (std::vector<std::string>{"ssgp"}));
  for (const char* bad : {"", "exact,", ",fitc", "exact,,fitc", "exact,exact", "exact,sparse"})
    EXPECT_THROW(parse_backend_list(bad), std::invalid_argument) << "'" << bad << "'";
}

}  // namespace
}  // namespace gpilqg::gp
