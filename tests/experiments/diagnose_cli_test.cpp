// `gpilqg diagnose` end to end: JSON with the fixed keys of
// docs/formats.md#diagnosis-json-gpilqg-diagnose---json on stdout and nothing else, the HDF5 report,
// plots, the add -> write-model -> model loop, and bad input (exit 2, "error:", the file and line or
// the option, and the valid choices). Plus the pieces of the analysis with closed-form answers: fit
// percent, the episode split, the cross-correlation band, the model file.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "diagnosis_support.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::quote;

/// A small cart-pole set with hidden Coulomb friction, mu = 1.2 N.
fs::path friction_csv(const fs::path& dir) {
  ModelSpec world;
  world = world.with(find_effect("cartpole", "cart_coulomb_friction"), Vector::Constant(1, 1.2));
  const fs::path file = dir / "friction.csv";
  write_measurements(file, test::hidden_effect_data(world.build(test::actuator_noise(1, 0.02)), 5));
  return file;
}


bool has_no_nan(const json& j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_structured())
    for (const auto& e : j)
      if (!has_no_nan(e)) return false;
  return true;
}

TEST(DiagnoseCli, JsonHasTheFixedKeysAndNamesTheHiddenEffect) {
  const fs::path dir = test::temporary_dir("diagnose_json");
  const fs::path data = friction_csv(dir);
  const auto result = test::run_cli("diagnose --system cartpole --data " + quote(data) + " --json" + test::kFastDiagnose);
  ASSERT_EQ(result.status, 0) << result.err;
  const json j = json::parse(result.out);  // one document and nothing else
  for (const char* key : {"system", "samples", "heldout_episodes", "consistent", "states", "relevance", "ranking", "verdict"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["system"], "cartpole");
  EXPECT_EQ(j["samples"], 7 * 119);
  EXPECT_FALSE(j["consistent"].get<bool>());
  for (const char* key : {"name", "rmse", "noise_floor", "fit_percent"}) EXPECT_TRUE(j["states"][0].contains(key)) << key;
  for (const char* key : {"effect", "parameters", "aliases", "explained", "heldout_rmse_before", "heldout_rmse_after"})
    EXPECT_TRUE(j["ranking"][0].contains(key)) << key;
  EXPECT_EQ(j["verdict"]["status"], "explained");
  EXPECT_EQ(j["verdict"]["effect"], "cart_coulomb_friction");
  EXPECT_NEAR(j["verdict"]["parameters"]["mu"].get<double>(), 1.2, 0.18);
  EXPECT_EQ(j["relevance"]["x_dot"].size(), 5u);
  EXPECT_TRUE(j["heldout_blocks"].is_null());  // several episodes are held out whole, never cut into blocks
  EXPECT_TRUE(has_no_nan(j));
  // Progress on stderr from the first moment; each candidate's line says the time so far and, but the
  // last, the time the others will take at that pace.
  EXPECT_EQ(result.err.rfind("diagnose: 840 samples in 7 episode(s)", 0), 0u) << result.err;
  std::istringstream lines(result.err);
  int candidates = 0, estimates = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.find(" fitted: ") == std::string::npos) continue;
    ++candidates;
    EXPECT_NE(line.find(" s so far"), std::string::npos) << line;
    estimates += line.find(" s for the other ") != std::string::npos;
  }
  EXPECT_GT(candidates, 5);
  EXPECT_EQ(estimates, candidates - 1) << result.err;
}

TEST(DiagnoseCli, AddWriteModelAndStartTheNextRoundFromIt) {
  const fs::path dir = test::temporary_dir("diagnose_loop");
  const fs::path data = friction_csv(dir);
  const fs::path model = dir / "model1.toml", report = dir / "report.h5";
  const auto added = test::run_cli("diagnose --system cartpole --data " + quote(data) + " --add cart_coulomb_friction --write-model " +
                                   quote(model) + " --out " + quote(report) + test::kFastDiagnose);
  ASSERT_EQ(added.status, 0) << added.err;
  EXPECT_NE(added.out.find("Add it and watch the error fall"), std::string::npos) << added.out;
  EXPECT_NE(added.out.find("sim+effect+GP"), std::string::npos) << added.out;
  // The report file is in place and no temporary file is left beside it.
  ASSERT_TRUE(fs::exists(report));
  for (const auto& entry : fs::directory_iterator(dir)) EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos);
  {
    H5::H5File h5(report.string(), H5F_ACC_RDONLY);
    EXPECT_TRUE(h5.nameExists("/compare/residual"));
    EXPECT_TRUE(h5.nameExists("/add/heldout_rmse"));
    EXPECT_TRUE(h5.nameExists("/ranking/explained"));
  }
  // The written model holds the fitted friction; the next diagnosis from it finds nothing left.
  const ModelSpec next = diagnosis::read_model_file(model, "cartpole");
  ASSERT_EQ(next.forces.size(), 1u);
  EXPECT_NEAR(next.forces[0].second(0), 1.2, 0.18);
  const auto again = test::run_cli("diagnose --system cartpole --data " + quote(data) + " --model " + quote(model) + " --json" + test::kFastDiagnose);
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(json::parse(again.out)["verdict"]["status"], "consistent") << again.out.substr(0, 2000);
}

TEST(DiagnoseCli, BadInputIsExitTwoNamingWhatIsWrong) {
  const fs::path dir = test::temporary_dir("diagnose_bad");
  const fs::path data = friction_csv(dir);
  const std::string base = "diagnose --system cartpole --data " + quote(data) + test::kFastDiagnose;
  auto unknown = test::run_cli(base + " --add cart_friction");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_EQ(unknown.err.rfind("error:", 0), 0u) << unknown.err;
  EXPECT_NE(unknown.err.find("cart_viscous_friction, cart_coulomb_friction"), std::string::npos) << unknown.err;
  auto value = test::run_cli(base + " --add cart_viscous_friction=fast");
  EXPECT_EQ(value.status, 2);
  EXPECT_NE(value.err.find("'fast' is not a number"), std::string::npos) << value.err;
  auto negative = test::run_cli(base + " --add param:cart_mass=-1");
  EXPECT_EQ(negative.status, 2);
  EXPECT_NE(negative.err.find("cart_mass"), std::string::npos) << negative.err;

  const fs::path model = dir / "bad.toml";
  std::ofstream(model) << "[model]\nsystem = \"cartpole\"\n\n[effects]\ncart_viscous_friction = 0.5\nwind = 2\n";
  auto bad_model = test::run_cli(base + " --model " + quote(model));
  EXPECT_EQ(bad_model.status, 2);
  EXPECT_NE(bad_model.err.find("bad.toml:line 6: field 'effects.wind'"), std::string::npos) << bad_model.err;
  EXPECT_NE(bad_model.err.find("quadratic_drag"), std::string::npos) << bad_model.err;

  auto missing = test::run_cli("diagnose --system cartpole --data " + quote(dir / "none.csv"));
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("none.csv"), std::string::npos) << missing.err;

  // A window longer than the episodes allow, and an empty one (was read as --window 0).
  auto long_window = test::run_cli(base + " --criterion simulation --window 500 --horizons 1,5");
  EXPECT_EQ(long_window.status, 2);
  EXPECT_NE(long_window.err.find("--window 500: longer than the data allow, at most"), std::string::npos) << long_window.err;
  auto empty_window = test::run_cli(base + " --criterion simulation --window ''");
  EXPECT_EQ(empty_window.status, 2);
  EXPECT_NE(empty_window.err.find("--window: '' is not a whole number"), std::string::npos) << empty_window.err;
  // --param beyond its range, named with the option.
  auto param = test::run_cli("simulate --system cartpole --param pole_length=1e300 --episodes 1 --steps 5 --out " +
                             quote(dir / "p.csv"));
  EXPECT_EQ(param.status, 2);
  EXPECT_NE(param.err.find("--param pole_length=1e+300: effect 'param:pole_length'"), std::string::npos) << param.err;

  // --search chooses how --auto searches; without --auto it would be ignored.
  auto search = test::run_cli(base + " --search forward");
  EXPECT_EQ(search.status, 2);
  EXPECT_NE(search.err.find("--search forward: chooses how --auto searches"), std::string::npos) << search.err;
}

// --exclude leaves candidates out (by name or pattern), says so in both reports, and refuses a pattern that
// names nothing or an excluded effect given to --add.
TEST(DiagnoseCli, ExcludeLeavesCandidatesOutAndSaysWhich) {
  const fs::path dir = test::temporary_dir("diagnose_exclude");
  const fs::path data = friction_csv(dir);
  const std::string base = "diagnose --system cartpole --data " + quote(data) + test::kFastDiagnose;
  const auto result = test::run_cli(base + " --exclude 'pole_*' --exclude actuator_gain --json");
  ASSERT_EQ(result.status, 0) << result.err;
  const json j = json::parse(result.out);
  EXPECT_EQ(j["excluded"], json::array({"pole_viscous_damping", "pole_coulomb_friction", "actuator_gain"}));
  for (const json& entry : j["ranking"]) {
    const std::string name = entry["effect"];
    EXPECT_EQ(name.rfind("pole_", 0), std::string::npos) << name;
    EXPECT_NE(name, "actuator_gain");
  }
  EXPECT_EQ(j["verdict"]["effect"], "cart_coulomb_friction");
  // The hidden effect itself excluded: it is never proposed, and the text report says what was left out.
  const auto without = test::run_cli(base + " --exclude cart_coulomb_friction");
  ASSERT_EQ(without.status, 0) << without.err;
  EXPECT_NE(without.out.find("excluded by --exclude (never ranked, searched or proposed): cart_coulomb_friction"),
            std::string::npos) << without.out;
  EXPECT_EQ(without.out.find("verdict: explained: cart_coulomb_friction"), std::string::npos) << without.out;

  const auto nothing = test::run_cli(base + " --exclude 'wind*'");
  EXPECT_EQ(nothing.status, 2);
  EXPECT_NE(nothing.err.find("--exclude 'wind*': matches no candidate effect"), std::string::npos) << nothing.err;
  EXPECT_NE(nothing.err.find("cart_viscous_friction"), std::string::npos) << nothing.err;
  const auto both = test::run_cli(base + " --exclude cart_coulomb_friction --add cart_coulomb_friction");
  EXPECT_EQ(both.status, 2);
  EXPECT_NE(both.err.find("--add cart_coulomb_friction: the effect is excluded"), std::string::npos) << both.err;
}

TEST(DiagnoseCli, SimulateAddsHiddenEffectsOfTheLibrary) {
  const fs::path dir = test::temporary_dir("simulate_effect");
  const std::string base = "simulate --system cartpole --episodes 2 --steps 20 --seed 3 --out ";
  ASSERT_EQ(test::run_cli(base + quote(dir / "plain.csv")).status, 0);
  const auto with = test::run_cli(base + quote(dir / "friction.csv") + " --effect cart_coulomb_friction=2");
  ASSERT_EQ(with.status, 0) << with.err;
  const auto plain = read_measurements(dir / "plain.csv", system_signature("cartpole"));
  const auto friction = read_measurements(dir / "friction.csv", system_signature("cartpole"));
  // Same seed, same excitation and noise: the first state agrees, the friction changes the rest.
  EXPECT_EQ(plain.episodes[0].x.row(0), friction.episodes[0].x.row(0));
  EXPECT_GT((plain.episodes[0].x - friction.episodes[0].x).cwiseAbs().maxCoeff(), 1e-3);
  const auto bad = test::run_cli(base + quote(dir / "bad.csv") + " --effect wind=2");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("cart_coulomb_friction"), std::string::npos) << bad.err;
}

TEST(DiagnoseCli, PlotsNeedMatplotlibAndSayWhenItIsMissing) {
  const fs::path dir = test::temporary_dir("diagnose_plots");
  const fs::path data = friction_csv(dir);
  // An interpreter without matplotlib (/bin/false fails every import) gives a clear error before any work.
  const std::string command = "GPILQG_PYTHON=/bin/false '" + test::program_path() + "' diagnose --system cartpole --data " +
                              quote(data) + " --plots " + quote(dir / "p") + " 2>" + quote(dir / "err.txt");
  const int status = std::system(command.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  std::ifstream err_file(dir / "err.txt");
  const std::string err((std::istreambuf_iterator<char>(err_file)), std::istreambuf_iterator<char>());
  EXPECT_NE(err.find("cannot import matplotlib and h5py"), std::string::npos) << err;
  if (std::system("/usr/bin/python3 -c 'import matplotlib, h5py' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no matplotlib/h5py: the PNG part is not checked here";
  const auto ok = test::run_cli("diagnose --system cartpole --data " + quote(data) + " --plots " + quote(dir / "p") + test::kFastDiagnose);
  ASSERT_EQ(ok.status, 0) << ok.err;
  for (const char* png : {"measured_vs_predicted.png", "residual_gp_band.png", "ranking.png", "residual_vs_input.png",
                          "residual_whiteness.png", "free_run.png"})
    EXPECT_GT(fs::file_size(dir / "p" / png), 1000u) << png;
}

TEST(DiagnoseCli, HorizonsAndTheTestsOfSystemIdentificationAreInEveryReport) {
  const fs::path dir = test::temporary_dir("diagnose_sysid");
  const fs::path data = friction_csv(dir), report = dir / "report.h5";
  const std::string base = "diagnose --system cartpole --data " + quote(data) + test::kFastDiagnose;
  const auto result = test::run_cli(base + " --horizons 1,5,20 --json --out " + quote(report));
  ASSERT_EQ(result.status, 0) << result.err;
  const json j = json::parse(result.out);
  ASSERT_EQ(j["k_step"].size(), 3u);
  EXPECT_EQ(j["k_step"][1]["k"], 5);
  EXPECT_EQ(j["k_step"][2]["k"], 20);
  for (const char* key : {"rmse", "fit_percent"}) EXPECT_TRUE(j["k_step"][2]["states"][0].contains(key)) << key;
  // Whiteness: band 1.96 / sqrt(N) over the held-out samples, one entry per state with L + 1 lags.
  const json& w = j["whiteness"];
  for (const char* key : {"band", "lags", "samples", "test", "level", "degrees_of_freedom", "critical_value", "states"})
    EXPECT_TRUE(w.contains(key)) << key;
  EXPECT_EQ(w["lags"], 20);
  EXPECT_NEAR(w["band"].get<double>(), 1.96 / std::sqrt(w["samples"].get<double>()), 1e-12);
  ASSERT_EQ(w["states"].size(), 4u);
  for (const char* key : {"name", "autocorrelation", "outside_band", "ljung_box_q", "p_value", "white"})
    EXPECT_TRUE(w["states"][0].contains(key)) << key;
  EXPECT_EQ(w["states"][0]["autocorrelation"].size(), 21u);
  // Free run: one entry per held-out episode, the three models (the verdict proposes the friction).
  ASSERT_EQ(j["free_run"].size(), j["heldout_episodes"].size());
  const json& run = j["free_run"][0];
  EXPECT_EQ(run["episode"], j["heldout_episodes"][0]);
  ASSERT_EQ(run["models"].size(), 3u);
  EXPECT_EQ(run["models"][0]["name"], "sim");
  EXPECT_EQ(run["models"][1]["name"], "sim+effect");
  EXPECT_EQ(run["models"][2]["name"], "sim+GP");
  EXPECT_FALSE(run["models"][0]["diverged"].get<bool>());
  EXPECT_EQ(run["models"][0]["fit_percent"].size(), 4u);
  EXPECT_TRUE(has_no_nan(j));
  {
    H5::H5File h5(report.string(), H5F_ACC_RDONLY);
    for (const char* name : {"/compare/k_5/fit_percent", "/compare/k_20/rmse", "/whiteness/autocorrelation",
                             "/whiteness/white", "/free_run/0/measured", "/free_run/0/predicted/sim+GP", "/free_run/0/fit_percent"})
      EXPECT_TRUE(h5.nameExists(name)) << name;
    EXPECT_FALSE(h5.nameExists("/heldout_blocks"));
  }
  // The text has a section for each.
  const auto text = test::run_cli(base + " --horizons 2");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("   k = 2 "), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("   k = 10 "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("\nWhiteness of the held-out residual"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("\nFree-run fit (k = inf) per held-out episode"), std::string::npos) << text.out;
}

TEST(DiagnoseCli, BadHorizonsAreExitTwoNamingTheOption) {
  const fs::path dir = test::temporary_dir("diagnose_bad_horizons");
  const fs::path data = friction_csv(dir);
  const std::string base = "diagnose --system cartpole --data " + quote(data) + test::kFastDiagnose + " --horizons ";
  for (const std::string value : {"0", "-1", "abc", "1,0", "5,x", "1.5", "2000000", "''"}) {
    const auto r = test::run_cli(base + value);
    EXPECT_EQ(r.status, 2) << value << ": " << r.out;
    EXPECT_EQ(r.err.rfind("error:", 0), 0u) << value << ": " << r.err;
    EXPECT_NE(r.err.find("--horizons"), std::string::npos) << value << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << value;
  }
  const auto twice = test::run_cli(base + "10,5,10");
  EXPECT_EQ(twice.status, 2);
  EXPECT_NE(twice.err.find("--horizons 10,5,10: 10 is listed twice"), std::string::npos) << twice.err;
  std::string many = "1";
  for (int k = 2; k <= 33; ++k) many += "," + std::to_string(k);
  const auto too_many = test::run_cli(base + many);
  EXPECT_EQ(too_many.status, 2);
  EXPECT_NE(too_many.err.find("33 horizons; expected at most 32"), std::string::npos) << too_many.err;
}

TEST(DiagnosisPieces, FitPercentHasItsClosedForm) {
  const Vector y = (Vector(4) << 1.0, 2.0, 3.0, 4.0).finished();
  EXPECT_DOUBLE_EQ(diagnosis::fit_percent(y, y), 100.0);
  // yhat = mean(y): |y - yhat| = |y - mean|, fit 0.
  EXPECT_NEAR(diagnosis::fit_percent(y, Vector::Constant(4, 2.5)), 0.0, 1e-12);
  // |y - mean| = sqrt(5); error 1 on one sample: 100 (1 - 1 / sqrt(5)).
  Vector off = y;
  off(0) += 1.0;
  EXPECT_NEAR(diagnosis::fit_percent(y, off), 100.0 * (1.0 - 1.0 / std::sqrt(5.0)), 1e-12);
  EXPECT_DOUBLE_EQ(diagnosis::fit_percent(Vector::Ones(3), Vector::Zero(3)), 0.0);
}

TEST(DiagnosisPieces, HeldOutEpisodesAreWholeAndSpread) {
  MeasurementSet set;
  set.system = system_signature("cartpole");
  for (int e = 0; e < 10; ++e) set.episodes.push_back({e, Vector::LinSpaced(3, 0.0, 0.04), Matrix::Zero(3, 4), Matrix::Zero(3, 1)});
  EXPECT_EQ(diagnosis::heldout_episodes(set, 0.3), (std::vector<int>{3, 6, 9}));
  const auto data = diagnosis::make_transitions(set, {3, 6, 9}, 0.02);
  EXPECT_EQ(data.size(), 20);
  EXPECT_EQ(data.rows(true).size(), 6u);
  set.episodes.resize(1);
  EXPECT_THROW(diagnosis::heldout_episodes(set, 0.3), diagnosis::DataProblem);  // the data's, named with its file
}

/// The data's file is named for what the data lack (a DataProblem: exit 2); any other
/// std::invalid_argument from inside the diagnosis is the program's own failure ("internal error",
/// exit 1) and never names the file as its cause.
TEST(DiagnosisPieces, OnlyTheDataProblemsBlameTheDataFile) {
  try {
    diagnosis::blame_for_diagnosis("F.h5", []() -> int { throw diagnosis::DataProblem("the data has 1 episode(s)"); });
    ADD_FAILURE() << "a DataProblem was swallowed";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "F.h5: the data has 1 episode(s)");
  }
  try {
    diagnosis::blame_for_diagnosis("F.h5", []() -> int { throw std::invalid_argument("d = 50.005; expected [0, 50]"); });
    ADD_FAILURE() << "the program's own failure was swallowed";
  } catch (const std::invalid_argument& e) {
    ADD_FAILURE() << "the program's own failure reported as bad input: " << e.what();
  } catch (const std::logic_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "the diagnosis failed on its own, not because of the data in F.h5: d = 50.005; expected [0, 50]");
    std::ostringstream err;
    EXPECT_EQ(run_reporting_errors([&]() -> int { throw e; }, err), kExitInternalFailure);
    EXPECT_EQ(err.str().rfind("internal error: ", 0), 0u) << err.str();
  }
  EXPECT_EQ(diagnosis::blame_for_diagnosis("F.h5", [] { return 7; }), 7);
}

/// Independent white residual and input: about 95% of the lags stay inside the band (binomial
/// bounds over 8 x 41 lags), and a residual that copies the input delayed by 3 steps peaks at lag 3.
TEST(DiagnosisPieces, CrossCorrelationBandHoldsForIndependentSeries) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> normal;
  int inside = 0, total = 0;
  for (int trial = 0; trial < 8; ++trial) {
    diagnosis::Transitions data;
    const int N = 2000;
    data.u.resize(N, 1);
    data.episode.assign(N, 0);
    Matrix r(N, 1), delayed(N, 1);
    for (int t = 0; t < N; ++t) {
      data.u(t, 0) = normal(rng);
      r(t, 0) = normal(rng);
    }
    for (int t = 0; t < N; ++t) delayed(t, 0) = t >= 3 ? data.u(t - 3, 0) + 0.1 * normal(rng) : 0.0;
    const auto xc = diagnosis::cross_correlation(data, r, 20);
    for (int k = 0; k < 41; ++k, ++total) inside += std::abs(xc.values[0][0](k)) <= xc.band(0, 0) ? 1 : 0;
    EXPECT_NEAR(xc.band(0, 0), 1.96 / std::sqrt(N), 0.3 / std::sqrt(N));
    const auto peak = diagnosis::cross_correlation(data, delayed, 20);
    Eigen::Index at = 0;
    peak.values[0][0].cwiseAbs().maxCoeff(&at);
    EXPECT_EQ(at - 20, 3);
  }
  EXPECT_GT(static_cast<double>(inside) / total, 0.91);
}

TEST(DiagnosisPieces, ModelFileRoundTrips) {
  ModelSpec model;
  model.preset = Preset::RealWorld;
  model = model.with(find_effect("cartpole", "param:cart_mass"), Vector::Constant(1, 1.25));
  model = model.with(find_effect("cartpole", "actuator_gain"), Vector::Constant(1, 0.9));
  model = model.with(find_effect("cartpole", "pole_viscous_damping"), Vector::Constant(1, 0.0123456789));
  const fs::path file = test::temporary_dir("model_file") / "m.toml";
  diagnosis::write_model_file(file, model, {"a comment"});
  const ModelSpec back = diagnosis::read_model_file(file, "cartpole");
  EXPECT_EQ(back.preset, Preset::RealWorld);
  EXPECT_EQ(back.parameters, model.parameters);
  EXPECT_EQ(back.actuator_gain, 0.9);
  ASSERT_EQ(back.forces.size(), 1u);
  EXPECT_EQ(back.forces[0].second(0), 0.0123456789);
  EXPECT_THROW(diagnosis::read_model_file(file, "quadrotor"), InputError);
  const auto request = diagnosis::parse_add_option("quadratic_drag=0.25", "cartpole");
  ASSERT_TRUE(request.values.has_value());
  EXPECT_EQ((*request.values)(0), 0.25);
  EXPECT_FALSE(diagnosis::parse_add_option("quadratic_drag", "cartpole").values.has_value());
}

}  // namespace
}  // namespace gpilqg

namespace gpilqg {
namespace {

// `--auto` through the command line: the path in the JSON and the HDF5 report, the final model written by
// --write-model with every effect found, its plot.
TEST(DiagnoseCli, AutoFindsTwoEffectsWritesTheFinalModelAndPlotsThePath) {
  const fs::path dir = test::temporary_dir("diagnose_auto");
  const fs::path data = dir / "two.csv", model = dir / "model.toml", report = dir / "report.h5";
  ASSERT_EQ(test::run_cli("simulate --system cartpole --preset sim --effect cart_coulomb_friction=1.5 --effect "
                          "external_force_x=0.8 --episodes 8 --steps 150 --out " + quote(data)).status, 0);
  const bool plots = std::system("/usr/bin/python3 -c 'import matplotlib, h5py' >/dev/null 2>&1") == 0;
  const auto result = test::run_cli("diagnose --system cartpole --data " + quote(data) + " --auto --json --write-model " +
                                    quote(model) + " --out " + quote(report) +
                                    (plots ? " --plots " + quote(dir / "p") : std::string()) + test::kFastDiagnose);
  ASSERT_EQ(result.status, 0) << result.err;
  const json j = json::parse(result.out);
  ASSERT_TRUE(j["selection"].is_object());
  std::set<std::string> found;
  for (const json& step : j["selection"]["steps"]) {
    found.insert(step["effect"].get<std::string>());
    // The share the step was accepted on (effect_test.hpp): at least 5% with z >= 3, on named channels
    // of the criterion, its interval around it.
    const json& judged = step["judged"];
    EXPECT_GE(judged["explained"].get<double>(), 0.05) << judged.dump();
    EXPECT_GE(judged["z_score"].get<double>(), 3.0) << judged.dump();
    EXPECT_LT(judged["explained_ci95"][0].get<double>(), judged["explained"].get<double>());
    EXPECT_GT(judged["explained_ci95"][1].get<double>(), judged["explained"].get<double>());
    ASSERT_FALSE(judged["channels"].empty());
    for (const json& channel : judged["channels"])
      EXPECT_TRUE(step["heldout_rmse_after_by_state"].contains(channel.get<std::string>())) << channel;
  }
  EXPECT_EQ(found, (std::set<std::string>{"cart_coulomb_friction", "external_force_x"})) << j["selection"].dump(1);
  EXPECT_TRUE(has_no_nan(j));
  const ModelSpec written = diagnosis::read_model_file(model, "cartpole");
  EXPECT_NEAR(written.current_values(find_effect("cartpole", "cart_coulomb_friction"))(0), 1.5, 0.15 * 1.5);
  EXPECT_NEAR(written.current_values(find_effect("cartpole", "external_force_x"))(0), 0.8, 0.15 * 0.8);
  H5::H5File h5(report.string(), H5F_ACC_RDONLY);
  EXPECT_EQ(h5.openDataSet("/selection/heldout_rmse").getSpace().getSimpleExtentNpoints(),
            static_cast<hssize_t>((j["selection"]["steps"].size() + 1) * 4));
  if (plots) {
    EXPECT_GT(fs::file_size(dir / "p" / "selection_path.png"), 1000u);
  }
}

}  // namespace
}  // namespace gpilqg
