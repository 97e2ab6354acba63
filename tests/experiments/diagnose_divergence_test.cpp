// `gpilqg diagnose` on data and models that overflow: measurements beyond the divergence bound are bad
// input (exit 2 naming the file, episode, time and column); a model that diverges on the data (a huge
// step dt, an absurd parameter, states where its predictions blow up) gets the verdict "model_diverges"
// with its counts, in the text, the JSON and the HDF5 report, and no NaN or inf anywhere.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "diagnosis_support.hpp"
#include "finite_checks.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;


using test::quote;

/// The cart-pole's "sim" preset with a little actuator noise: 7 episodes of 120 samples at 0.02 s.
MeasurementSet plain_data() {
  const ModelSpec world;
  return test::hidden_effect_data(world.build(test::actuator_noise(1, 0.02)), 5);
}

fs::path write_csv(const fs::path& dir, const std::string& name, const MeasurementSet& set) {
  const fs::path file = dir / name;
  write_measurements(file, set);
  return file;
}

std::string string_attribute(const fs::path& file, const std::string& name) {
  const H5::H5File h5(file.string(), H5F_ACC_RDONLY);
  const H5::Attribute attribute = h5.openAttribute(name);
  std::string value;
  attribute.read(attribute.getDataType(), value);
  return value;
}

/// Runs the diagnosis three ways (text, --json, --out) and checks that each says the model diverges,
/// that no report holds a NaN or inf, and returns the JSON document.
json expect_model_diverges(const std::string& arguments, const fs::path& dir) {
  const auto text = test::run_cli(arguments);
  EXPECT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("=> the model diverges on the data: "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("3. Which effect is missing: not ranked, the model diverges on the data"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("verdict: model_diverges\n  the model diverges"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("consistent with the measurements"), std::string::npos) << text.out;
  // No number prints as nan or inf (the free-run heading's "k = inf" is the one inf in words).
  std::string numbers = text.out;
  for (std::size_t at = numbers.find("(k = inf)"); at != std::string::npos; at = numbers.find("(k = inf)")) numbers.erase(at, 9);
  for (const char* word : {"nan", "inf%", " inf"}) EXPECT_EQ(numbers.find(word), std::string::npos) << word << "\n" << text.out;
  // The free run of a diverging model is flagged, never a NaN.
  EXPECT_NE(text.out.find("Free-run fit (k = inf) per held-out episode"), std::string::npos) << text.out;

  const fs::path report = dir / "report.h5";
  const auto result = test::run_cli(arguments + " --json --out " + quote(report));
  EXPECT_EQ(result.status, 0) << result.err;
  const json j = json::parse(result.out);
  EXPECT_EQ(j["verdict"]["status"], "model_diverges");
  EXPECT_TRUE(j["verdict"]["effect"].is_null());
  EXPECT_FALSE(j["consistent"].get<bool>());
  EXPECT_TRUE(j["model_diverges"].get<bool>());
  EXPECT_TRUE(j["ranking"].empty());
  EXPECT_EQ(j["divergence"]["bound"].get<double>(), 1e12);
  EXPECT_TRUE(test::json_numbers_finite(j));

  EXPECT_TRUE(test::hdf5_datasets_finite(report));
  EXPECT_EQ(string_attribute(report, "status"), "model_diverges");
  EXPECT_TRUE(test::json_numbers_finite(json::parse(string_attribute(report, "report"))));
  return j;
}

TEST(DiagnoseDivergenceCli, StatesWhereTheModelBlowsUpAreNotConsistent) {
  // States of 1e6 (velocities of 1e6 m/s and rad/s): the measurements are within the bound, the
  // model's open-loop predictions from them are not. Once reported "consistent".
  const fs::path dir = test::temporary_dir("diagnose_diverging_states");
  MeasurementSet set = plain_data();
  for (Episode& e : set.episodes) e.x *= 1e6;
  const json j = expect_model_diverges("diagnose --system cartpole --data " + quote(write_csv(dir, "big.csv", set)) + test::kFastDiagnose, dir);
  // Most windows diverge, and the counts are in the JSON and in the reason.
  const int diverged = j["divergence"]["k_step"]["diverged"], windows = j["divergence"]["k_step"]["windows"];
  EXPECT_GT(2 * diverged, windows) << j["divergence"].dump();
  for (const auto& k : j["k_step"]) EXPECT_GT(k["diverged"].get<int>(), 0) << k.dump();
  const std::string reason = j["verdict"]["reason"];
  EXPECT_NE(reason.find(fmt::format("{} of {} k-step windows", diverged, windows)), std::string::npos) << reason;
}

TEST(DiagnoseDivergenceCli, AHugeTimeStepMakesTheModelDiverge) {
  const fs::path dir = test::temporary_dir("diagnose_huge_dt");
  MeasurementSet set = plain_data();
  for (Episode& e : set.episodes)
    for (Eigen::Index s = 0; s < e.t.size(); ++s) e.t(s) = 1e300 * static_cast<double>(s);
  const json j = expect_model_diverges("diagnose --system cartpole --data " + quote(write_csv(dir, "dt.csv", set)) + test::kFastDiagnose, dir);
  EXPECT_EQ(j["divergence"]["one_step"]["diverged"], j["samples"]);
}

TEST(DiagnoseDivergenceCli, AModelWithAnAbsurdParameterDiverges) {
  // A pole of 1e300 m (once "explained -1.5e302% +- inf%" for every candidate effect) is no physical
  // model and is refused where it is read; the shortest pole the range allows, a micrometre, swings far
  // too fast for the data's step, and the model diverges on them.
  const fs::path dir = test::temporary_dir("diagnose_absurd_model");
  const fs::path data = write_csv(dir, "plain.csv", plain_data());
  const fs::path absurd = dir / "absurd.toml";
  std::ofstream(absurd) << "[model]\nsystem = \"cartpole\"\npreset = \"sim\"\n[parameters]\npole_length = 1e300\n";
  const auto refused = test::run_cli("diagnose --system cartpole --data " + quote(data) + " --model " + quote(absurd));
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.err.find("absurd.toml:line 5: field 'parameters.pole_length'"), std::string::npos) << refused.err;
  const fs::path model = dir / "pole.toml";
  std::ofstream(model) << "[model]\nsystem = \"cartpole\"\npreset = \"sim\"\n[parameters]\npole_length = 1e-6\n";
  const std::string base = "diagnose --system cartpole --data " + quote(data) + " --model " + quote(model) + test::kFastDiagnose;
  expect_model_diverges(base, dir);
  // Adding an effect to it fits and scores the effect with finite numbers, and still says so.
  const auto added = test::run_cli(base + " --add cart_viscous_friction --json");
  ASSERT_EQ(added.status, 0) << added.err;
  const json j = json::parse(added.out);
  EXPECT_EQ(j["verdict"]["status"], "model_diverges");
  EXPECT_TRUE(test::json_numbers_finite(j));
}

TEST(DiagnoseDivergenceCli, MeasurementsBeyondTheBoundAreBadInput) {
  // Cells of +-1e308 are finite, but their differences are not: rejected when read, naming the cell.
  const fs::path dir = test::temporary_dir("diagnose_huge_cells");
  MeasurementSet set = plain_data();
  set.episodes[1].x(3, 1) = 1e308;
  set.episodes[1].x(4, 1) = -1e308;
  const fs::path data = write_csv(dir, "cells.csv", set);
  const auto r = test::run_cli("diagnose --system cartpole --data " + quote(data) + test::kFastDiagnose + " --json");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(r.out.empty()) << r.out;
  const std::string expected = fmt::format("error: {}: episode {} at t = {}: column 'x_dot' is 1e+308; expected |value| <= 1e+12",
                                           data.string(), set.episodes[1].id, set.episodes[1].t(3));
  EXPECT_EQ(r.err.rfind(expected, 0), 0u) << r.err << "\nexpected: " << expected;
  // A control beyond the bound too.
  set = plain_data();
  set.episodes[0].u(2, 0) = -2e12;
  const auto control = test::run_cli("diagnose --system cartpole --data " + quote(write_csv(dir, "u.csv", set)) + test::kFastDiagnose);
  EXPECT_EQ(control.status, 2);
  EXPECT_NE(control.err.find("column 'force' is -2e+12; expected |value| <= 1e+12"), std::string::npos) << control.err;
}

}  // namespace
}  // namespace gpilqg
