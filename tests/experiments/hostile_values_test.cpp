/// Hostile values that a format admits but no meaning does: NaN, inf and numbers whose arithmetic
/// overflows, limits out of order, names a CSV cannot hold, an output name of the wrong format. Each
/// is refused on reading, naming the file and the attribute, dataset or field (exit 2 on the command
/// line), or computed so that finite input gives finite output (docs/reliability.md).

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/output_path.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/data_info.hpp"
#include "gpilqg/experiments/plan_config.hpp"
#include "gpilqg/experiments/policy_file.hpp"
#include "gpilqg/experiments/run_config.hpp"
#include "gpilqg/experiments/solve_config.hpp"
#include "gpilqg/experiments/toml_fields.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

using test::quote;

/// `text` with its first `from` replaced by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// ---- output names of a fixed format ---------------------------------------------------------------

TEST(HostileValues, AnOutputNameMustCarryItsFormatsExtension) {
  const OutputFormat policy{"plan writes an HDF5 policy file", kHdf5Extensions};
  const OutputFormat log{"rollout writes a log (CSV or HDF5)", kMeasurementExtensions};
  EXPECT_EQ(output_extension_problem("p.csv", policy), "plan writes an HDF5 policy file; expected a name ending in .h5 or .hdf5");
  EXPECT_EQ(output_extension_problem("out/p", policy), "plan writes an HDF5 policy file; expected a name ending in .h5 or .hdf5");
  EXPECT_EQ(output_extension_problem("p.h5.tmp", policy), "plan writes an HDF5 policy file; expected a name ending in .h5 or .hdf5");
  EXPECT_EQ(output_extension_problem("log.txt", log),
            "rollout writes a log (CSV or HDF5); expected a name ending in .csv, .h5 or .hdf5");
  for (const char* good : {"p.h5", "dir.csv/p.hdf5", "P.H5", "p.HDF5"}) EXPECT_EQ(output_extension_problem(good, policy), std::nullopt) << good;
  for (const char* good : {"log.csv", "LOG.CSV", "log.h5"}) EXPECT_EQ(output_extension_problem(good, log), std::nullopt) << good;
}

/// Every output option of a fixed format, with a name of another format: exit 2 before any work.
TEST(HostileValuesCli, EveryCommandRefusesAnOutputNameOfAnotherFormat) {
  const fs::path dir = test::temporary_dir("hostile_extensions");
  const std::string plan = quote(test::write_text(dir / "plan.toml", test::kTinyPlan));
  test::write_text(dir / "run.toml", test::kTinyRun);
  const std::string sweep =
      quote(test::write_text(dir / "sweep.toml", "system = \"cartpole\"\nconfig = \"run.toml\"\n[grid]\n\"loop.rollouts\" = [1, 2]\n"));
  struct Case {
    std::string arguments, message;
  };
  // Absolute names in the test's folder and tiny configs: were a name accepted, the work stays small.
  const auto in = [&](const std::string& name) { return quote(dir / name); };
  const std::string run = "run cartpole --config " + in("run.toml") + " --no-plots";
  const std::vector<Case> cases = {
      {"plan " + plan + " --out " + in("p.csv"), "p.csv: plan writes an HDF5 policy file; expected a name ending in .h5 or .hdf5"},
      {run + " --out " + in("r.csv"), "r.csv: run writes an HDF5 result file; expected a name ending in .h5"},
      {"merge a.h5 b.h5 --no-plots --out " + in("m.json"), "m.json: merge writes an HDF5 result file"},
      {"sweep " + sweep + " --no-plots --out " + in("s.toml"), "s.toml: sweep writes an HDF5 result file"},
      {"simulate --system cartpole --episodes 1 --steps 5 --out " + in("d.txt"),
       "d.txt: simulate writes a measurement file (CSV or HDF5); expected a name ending in .csv, .h5 or .hdf5"},
      {"rollout --system cartpole --policy p.h5 --out " + in("log"), "log: rollout writes a log (CSV or HDF5)"},
      {"diagnose --system cartpole --data d.csv --out " + in("r.csv"), "r.csv: diagnose writes an HDF5 report"},
      {"diagnose --system cartpole --data d.csv --write-model " + in("m.h5"),
       "m.h5: diagnose writes a TOML model file; expected a name ending in .toml"},
      {"profile d.h5 --backends exact --out " + in("p.json"), "p.json: profile writes an HDF5 result file"},
      {"data import log.csv --system cartpole --map m.toml --out " + in("set.txt"), "set.txt: data import writes a measurement file"},
  };
  for (const Case& c : cases) {
    const auto r = test::run_cli(c.arguments);
    EXPECT_EQ(r.status, 2) << c.arguments << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.arguments << "\n" << r.err;
  }
  for (const char* name : {"p.csv", "r.csv", "m.json", "s.toml", "d.txt", "log", "m.h5", "p.json", "set.txt"})
    EXPECT_FALSE(fs::exists(dir / name)) << name;
}

TEST(HostileValuesCli, AnEmptyBackendListIsRefusedNamingTheOption) {
  const fs::path dir = test::temporary_dir("hostile_backends");
  const std::string run = "run cartpole --no-plots --config " + quote(test::write_text(dir / "run.toml", test::kTinyRun));
  for (const char* list : {"''", "','", "'exact,'"}) {
    const auto r = test::run_cli(fmt::format("{} --backends {} --out {}", run, list, quote(dir / "never.h5")));
    EXPECT_EQ(r.status, 2) << list << "\n" << r.err;
    EXPECT_NE(r.err.find("--backends: backend list"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("empty entry"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "never.h5"));
}

// ---- policy files --------------------------------------------------------------------------------

/// A valid cart-pole policy of two steps, limited to [-25, 25].
PolicyFile small_policy() {
  PolicyFile p;
  p.system = "cartpole";
  p.state_names = {"x", "x_dot", "theta", "theta_dot"};
  p.control_names = {"force"};
  p.dt = 0.05;
  p.policy.x_bar = Matrix::Zero(4, 3);
  p.policy.u_bar = Matrix::Zero(1, 2);
  p.policy.k = Matrix::Zero(1, 2);
  p.policy.K = {Matrix::Zero(1, 4), Matrix::Zero(1, 4)};
  p.policy.u_min = Vector::Constant(1, -25.0);
  p.policy.u_max = Vector::Constant(1, 25.0);
  p.gpilqg_version = "test";
  return p;
}

/// Replaces the numeric attribute `name` of /policy (of any shape) with `values`.
void set_attribute(const fs::path& file, const std::string& name, const std::vector<double>& values) {
  H5::H5File h5(file.string(), H5F_ACC_RDWR);
  H5::Group group = h5.openGroup("/policy");
  if (group.attrExists(name)) group.removeAttr(name);
  const hsize_t size = values.size();
  H5::Attribute attribute = group.createAttribute(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &size));
  attribute.write(H5::PredType::NATIVE_DOUBLE, values.data());
}

/// Overwrites entry `index` (flat, row-major) of the dataset /policy/<name>.
void set_entry(const fs::path& file, const std::string& name, std::size_t index, double value) {
  H5::H5File h5(file.string(), H5F_ACC_RDWR);
  H5::DataSet dataset = h5.openDataSet("/policy/" + name);
  std::vector<double> values(static_cast<std::size_t>(dataset.getSpace().getSimpleExtentNpoints()));
  dataset.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  values[index] = value;
  dataset.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

void set_string_attribute(const fs::path& file, const std::string& name, const std::string& value) {
  H5::H5File h5(file.string(), H5F_ACC_RDWR);
  H5::Group group = h5.openGroup("/policy");
  if (group.attrExists(name)) group.removeAttr(name);
  const H5::StrType type(H5::PredType::C_S1, value.size() + 1);
  group.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value.c_str());
}

std::string reading_error(const fs::path& file, const std::string& system = "cartpole") {
  try {
    check_policy_system(read_policy_file(file), file, system);
  } catch (const InputError& e) {
    return e.what();
  }
  return "read";
}

TEST(HostileValues, APolicyFileOfNonFiniteOrDisorderedValuesIsRefusedNamingTheAttribute) {
  const fs::path dir = test::temporary_dir("hostile_policy");
  struct Case {
    const char* name;
    std::function<void(const fs::path&)> damage;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"u_min_nan", [](const fs::path& f) { set_attribute(f, "u_min", {kNaN}); },
       "attribute '/policy@u_min': entry 0 is nan; expected finite numbers"},
      {"u_max_inf", [](const fs::path& f) { set_attribute(f, "u_max", {kInf}); },
       "attribute '/policy@u_max': entry 0 is inf; expected finite numbers"},
      {"limits_crossed", [](const fs::path& f) { set_attribute(f, "u_min", {30.0}); },
       "attribute '/policy@u_min': entry 0 is 30, above u_max's 25; expected u_min <= u_max"},
      {"dt_nan", [](const fs::path& f) { set_attribute(f, "dt", {kNaN}); },
       "attribute '/policy@dt': is nan; expected a finite number > 0"},
      {"dt_negative", [](const fs::path& f) { set_attribute(f, "dt", {-0.05}); },
       "attribute '/policy@dt': is -0.05; expected a finite number > 0"},
      {"cost_inf", [](const fs::path& f) { set_attribute(f, "expected_cost", {kInf}); },
       "attribute '/policy@expected_cost': is inf; expected a finite number"},
      {"round_fraction", [](const fs::path& f) { set_attribute(f, "round", {1.5}); },
       "attribute '/policy@round' is 1.5; expected a whole number in [0, 1000000]"},
      {"x_bar_nan", [](const fs::path& f) { set_entry(f, "x_bar", 6, kNaN); },
       "dataset '/policy/x_bar': entry [1, 2] is nan; expected finite numbers"},
      {"u_bar_inf", [](const fs::path& f) { set_entry(f, "u_bar", 1, -kInf); },
       "dataset '/policy/u_bar': entry [1, 0] is -inf; expected finite numbers"},
      {"gain_nan", [](const fs::path& f) { set_entry(f, "K", 7, kNaN); },
       "dataset '/policy/K': entry [1, 0, 3] is nan; expected finite numbers"},
      {"other_system", [](const fs::path& f) { set_string_attribute(f, "system", "quadrotor"); },
       "attribute '/policy@system' is 'quadrotor'; expected 'cartpole', the system it is used for"},
      {"no_system", [](const fs::path& f) { set_string_attribute(f, "system", ""); },
       "attribute '/policy@system': is empty; expected the name of the planned system"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path file = dir / (std::string(c.name) + ".h5");
    write_policy_file(file, small_policy(), nullptr);
    ASSERT_EQ(reading_error(file), "read");
    c.damage(file);
    EXPECT_EQ(reading_error(file), file.string() + ": " + c.message);
  }
}

TEST(HostileValues, APolicyOfAModelFileMatchesTheSameModelInAnotherFolder) {
  const fs::path dir = test::temporary_dir("hostile_policy_model");
  const fs::path file = dir / "p.h5";
  write_policy_file(file, small_policy(), nullptr);
  set_string_attribute(file, "system", "configs/../models/arm.xml");
  EXPECT_EQ(reading_error(file, "/robot/arm.xml"), "read");
  EXPECT_NE(reading_error(file, "/robot/hand.xml").find("attribute '/policy@system' is 'configs/../models/arm.xml'"),
            std::string::npos);
  EXPECT_NE(reading_error(file, "cartpole").find("expected 'cartpole'"), std::string::npos);
}

TEST(HostileValuesCli, RolloutAndPlanRefuseABadPolicyWithExit2) {
  const fs::path dir = test::temporary_dir("hostile_policy_cli");
  const fs::path crossed = dir / "crossed.h5", other = dir / "other.h5";
  write_policy_file(crossed, small_policy(), nullptr);
  set_attribute(crossed, "u_min", {30.0});
  write_policy_file(other, small_policy(), nullptr);
  set_string_attribute(other, "system", "quadrotor");
  const std::string plan = quote(test::write_text(dir / "plan.toml", replaced(test::kTinyPlan, "horizon = 15", "horizon = 2")));
  struct Case {
    std::string arguments, message;
  };
  const std::vector<Case> cases = {
      {"rollout --system cartpole --policy " + quote(crossed) + " --out " + quote(dir / "log.csv"),
       crossed.string() + ": attribute '/policy@u_min': entry 0 is 30, above u_max's 25"},
      {"rollout --system cartpole --policy " + quote(other) + " --out " + quote(dir / "log.csv"),
       other.string() + ": attribute '/policy@system' is 'quadrotor'; expected 'cartpole'"},
      {"plan " + plan + " --previous " + quote(other) + " --out " + quote(dir / "next.h5"),
       other.string() + ": attribute '/policy@system' is 'quadrotor'; expected 'cartpole'"},
  };
  for (const Case& c : cases) {
    const auto r = test::run_cli(c.arguments);
    EXPECT_EQ(r.status, 2) << c.arguments << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.arguments << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "log.csv"));
  EXPECT_FALSE(fs::exists(dir / "next.h5"));
}

// ---- cost weights ---------------------------------------------------------------------------------

std::string config_error(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "read";
}

TEST(HostileValues, CostWeightsBeyondTheBoundAreRefusedInEveryConfigNamingFieldAndEntry) {
  const auto plan = [](const std::string& from, const std::string& to) {
    const std::string text = replaced(test::kTinyPlan, from, to);
    return config_error([&] {
      const toml::table root = TomlFields::parse_text(text, "plan.toml");
      read_plan_config(TomlFields(root, "plan.toml"));
    });
  };
  const auto run = [](const std::string& from, const std::string& to) {
    const std::string text = replaced(test::kTinyRun, from, to);
    return config_error([&] { parse_run_config("cartpole", text, "run.toml"); });
  };
  const std::string bound = "expected a weight in [0, 1e+150]";
  EXPECT_NE(plan("Qf = [10.0, 10.0, 10.0, 10.0]", "Qf = [10.0, 1e308, 10.0, 10.0]")
                .find("field 'problem.Qf': entry 1 is 1e+308; " + bound),
            std::string::npos);
  EXPECT_NE(plan("Q = [1.0, 1.0, 1.0, 1.0]", "Q = [1.0, 1.0, 1.0, 1e151]").find("field 'problem.Q': entry 3 is 1e+151"),
            std::string::npos);
  EXPECT_NE(plan("R = [0.1]", "R = [1e200]").find("field 'problem.R': entry 0 is 1e+200; " + bound), std::string::npos);
  EXPECT_EQ(plan("Qf = [10.0, 10.0, 10.0, 10.0]", "Qf = [1e150, 1e150, 1e150, 1e150]"), "read");
  EXPECT_NE(run("Qf = [10.0, 10.0, 10.0, 10.0]", "Qf = [1e308, 10.0, 10.0, 10.0]").find("field 'tasks[0].Qf': entry 0 is 1e+308"),
            std::string::npos);
  EXPECT_NE(run("R = [0.1]", "R = [1e300]").find("field 'tasks[0].R': entry 0 is 1e+300; " + bound), std::string::npos);
}

TEST(HostileValues, TheWeightBoundKeepsTheCostOfStatesWithinTheDivergenceBoundFinite) {
  // The worst case of the bound's derivation (core/limits.hpp): every weight at the bound, every
  // state and the goal at opposite ends of the divergence bound, the longest horizon.
  const int n = 4;
  const QuadraticCost cost(1.0, Vector::Constant(n, limits::kMaxCostWeight).asDiagonal(),
                           Vector::Constant(1, limits::kMaxCostWeight).asDiagonal(),
                           Vector::Constant(n, limits::kMaxCostWeight).asDiagonal(), Vector::Constant(n, -1e12));
  const Vector x = Vector::Constant(n, 1e12), u = Vector::Constant(1, 1e12);
  const double stage = cost.stage(0, x, u);
  EXPECT_TRUE(std::isfinite(stage * static_cast<double>(limits::kMaxHorizon) + cost.terminal(x)));
}

TEST(HostileValuesCli, AnOverflowingCostIsReportedAsOverflowNotAsDivergence) {
  // The solver cuts a diverging trajectory at the bound, so the cost of what it returns is finite
  // exactly when the states diverged; not finite, the cost itself overflowed.
  EXPECT_NE(initial_rollout_failure(kInf).find("keep every state within the divergence bound (|x| <= 1e+12), but their "
                                               "cost overflowed"),
            std::string::npos);
  EXPECT_NE(initial_rollout_failure(1.075e23).find("drive the model beyond the divergence bound"), std::string::npos);
  // End to end: the cart-pole at rest stays at rest whatever the step, so only the cost (a goal 1e12
  // away, weights at the bound, a step of 1e140 s) leaves the doubles.
  const fs::path dir = test::temporary_dir("hostile_cost_overflow");
  const std::string text = R"([system]
name = "cartpole"
integrator = "euler"
dt = 1e140
[problem]
horizon = 1
x0 = [0.0, 0.0, 0.0, 0.0]
goal = [1e12, 0.0, 0.0, 0.0]
Q = [1e150, 1.0, 1.0, 1.0]
R = [0.1]
Qf = [10.0, 10.0, 10.0, 10.0]
)";
  const auto r = test::run_cli("solve " + quote(test::write_text(dir / "overflow.toml", text)));
  EXPECT_NE(r.err.find("warning: not converged: the initial controls keep every state within the divergence bound "
                       "(|x| <= 1e+12), but their cost overflowed"),
            std::string::npos)
      << r.err;
}

// ---- statistics of extreme but finite data -------------------------------------------------------

TEST(HostileValues, StatisticsOfExtremeFiniteDataAreFinite) {
  MeasurementSet set;
  set.system = system_signature("cartpole");
  Episode e;
  e.t = Vector(3);
  e.t << -1e308, 0.0, 1e308;  // a step of 1e308 s; the span of 2e308 s is beyond a double
  e.x = Matrix(3, 4);
  e.x << 1e308, -1e308, 1.7e308, 0.0,  //
      -1e308, 1e308, 1.7e308, 0.0,     //
      1e308, 1e308, 1.7e308, 1e-300;
  e.u = Matrix(3, 1);
  e.u << -1.7e308, 1.7e308, 0.0;
  set.episodes.push_back(e);
  const MeasurementSummary s = summarize(set);
  EXPECT_EQ(s.dt_min, 1e308);
  EXPECT_EQ(s.dt_max, 1e308);
  EXPECT_EQ(s.duration, kInf);  // not representable: the callers say so
  for (const auto* columns : {&s.states, &s.controls})
    for (const ColumnSummary& c : *columns) {
      SCOPED_TRACE(c.name);
      for (const double statistic : {c.min, c.max, c.mean, c.std}) EXPECT_TRUE(std::isfinite(statistic));
    }
  EXPECT_NEAR(s.states[0].mean, 1e308 / 3.0, 1e294);
  EXPECT_NEAR(s.states[0].std, std::sqrt(8.0 / 9.0) * 1e308, 1e294);
  EXPECT_EQ(s.states[2].mean, 1.7e308);
  EXPECT_EQ(s.states[2].std, 0.0);
  EXPECT_NEAR(s.controls[0].std, std::sqrt(2.0 / 3.0) * 1.7e308, 1e294);

  const nlohmann::json j = data_info_json("extreme.csv", summarize(set));
  EXPECT_EQ(j.at("dt"), 1e308);
  EXPECT_EQ(j.at("duration_s"), "not representable (beyond 1.8e308)");
  for (const auto& column : j.at("states")) EXPECT_TRUE(column.at("std").is_number()) << column.dump();
  EXPECT_FALSE(j.dump().find("null") != std::string::npos) << j.dump();
  EXPECT_NE(format_data_info("extreme.csv", summarize(set)).find("duration  not representable (beyond 1.8e308)"),
            std::string::npos);
}

// ---- names a measurement file cannot hold ----------------------------------------------------------

TEST(HostileValuesCli, ModelNamesThatACsvCannotHoldAreRefusedOnLoading) {
  EXPECT_EQ(column_name_problem("a b\"c "), std::nullopt);  // read back as written: fields are not trimmed
  const fs::path dir = test::temporary_dir("hostile_names");
  const auto model = [&](const std::string& file, const std::string& joint, const std::string& actuator) {
    return test::write_text(dir / file, fmt::format(R"(<mujoco model="m">
  <worldbody><body name="b"><joint name="{}" type="slide" axis="1 0 0"/><geom type="box" size="0.1 0.1 0.1" mass="1"/></body></worldbody>
  <actuator><motor name="{}" joint="{}"/></actuator>
</mujoco>)",
                                         joint, actuator, joint));
  };
  struct Case {
    fs::path file;
    std::string message;
  };
  const std::vector<Case> cases = {
      {model("comma.xml", "a,b", "drive"), "joint 0 name 'a,b' contains a comma, which separates CSV fields"},
      {model("newline.xml", "a&#10;b", "drive"), "joint 0 name 'a\nb' contains a line break"},
      {model("actuator.xml", "slide", "left,right"), "actuator 0 name 'left,right' contains a comma"},
      {model("time.xml", "t", "drive"), "joint 0 name 't' is 't', a fixed column of measurement files"},
      {model("twice.xml", "slide", "slide_dot"), "the state or control name 'slide_dot' occurs twice"},
  };
  for (const Case& c : cases) {
    std::string message = "loaded";
    try {
      system_signature(c.file.string());
    } catch (const std::exception& e) {
      message = e.what();
    }
    EXPECT_NE(message.find(c.file.string() + ": " + c.message), std::string::npos) << message;
  }
  const auto r = test::run_cli("simulate --system " + quote(cases[0].file) + " --episodes 1 --steps 5 --out " +
                               quote(dir / "never.csv"));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("joint 0 name 'a,b' contains a comma"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "never.csv"));
  EXPECT_EQ(system_signature(model("spaced.xml", " slide ", "drive&quot;").string()).states[0].name, " slide ");
}

}  // namespace
}  // namespace gpilqg
