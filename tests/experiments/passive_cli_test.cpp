// Systems without controls (passive systems) and URDF robots through the command line: free-swing
// data of the passive pendulum (data/pendulum_passive.xml) with a hidden joint damping through
// `simulate`, `data info` and `diagnose` (text, JSON, HDF5 report), which must find the damping; the
// refusals of solve, plan, rollout and run; the URDF arm (data/two_link_arm.urdf) through simulate
// and diagnose.

#include <gtest/gtest.h>

#include <cmath>

#include <H5Cpp.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::quote;
fs::path pendulum_model() { return test::source_dir() / "data" / "pendulum_passive.xml"; }
fs::path urdf_arm() { return test::source_dir() / "data" / "two_link_arm.urdf"; }

/// Free swings of the pendulum with `world` (e.g. "--param swing.damping=0.3"): 6 episodes of 150
/// samples at 0.02 s, sensor noise 0.001.
fs::path simulate_pendulum(const fs::path& dir, const std::string& world) {
  const fs::path file = dir / "swing.csv";
  const auto r = test::run_cli("simulate --system " + quote(pendulum_model()) + " " + world +
                               " --episodes 6 --steps 150 --observation-noise 0.001 --seed 2 --out " + quote(file));
  EXPECT_EQ(r.status, 0) << r.err;
  return file;
}

TEST(PassiveCli, SimulateWritesStatesOnlyAndDataInfoReadsThem) {
  const fs::path dir = test::temporary_dir("passive_simulate");
  const fs::path data = simulate_pendulum(dir, "");
  std::ifstream in(data);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "episode,t,swing,swing_dot");
  const auto info = test::run_cli("data info " + quote(data) + " --system " + quote(pendulum_model()) + " --json");
  ASSERT_EQ(info.status, 0) << info.err;
  const json j = json::parse(info.out);
  EXPECT_EQ(j["system"], "pendulum_passive");
  EXPECT_EQ(j["episodes"], 6) << info.out;
  const auto text = test::run_cli("data info " + quote(data) + " --system " + quote(pendulum_model()));
  EXPECT_EQ(text.status, 0) << text.err;
  // The free swings span the angle: the initial states are spread, there is no other excitation.
  const auto h5 = test::run_cli("simulate --system " + quote(pendulum_model()) + " --episodes 2 --steps 20 --out " +
                                quote(dir / "swing.h5"));
  ASSERT_EQ(h5.status, 0) << h5.err;
  EXPECT_EQ(test::run_cli("data info " + quote(dir / "swing.h5") + " --system " + quote(pendulum_model())).status, 0);
  // No actuators, no actuator noise.
  const auto noisy = test::run_cli("simulate --system " + quote(pendulum_model()) + " --actuator-noise 0.1 --out " +
                                   quote(dir / "noisy.csv"));
  EXPECT_EQ(noisy.status, 2);
  EXPECT_NE(noisy.err.find("--actuator-noise"), std::string::npos) << noisy.err;
  EXPECT_NE(noisy.err.find("no controls"), std::string::npos) << noisy.err;
}

TEST(PassiveCli, DiagnoseFindsAHiddenJointDamping) {
  const fs::path dir = test::temporary_dir("passive_diagnose");
  const fs::path data = simulate_pendulum(dir, "--param swing.damping=0.3");
  const fs::path report = dir / "report.h5";
  // One run: the text report on stdout, the JSON document inside the HDF5 report, and the plots
  // (when /usr/bin/python3 has matplotlib and h5py).
  const bool plots = std::system("/usr/bin/python3 -c 'import matplotlib, h5py' >/dev/null 2>&1") == 0;
  const auto r = test::run_cli("diagnose --system " + quote(pendulum_model()) + " --data " + quote(data) +
                               " --gp-points 100 --out " + quote(report) +
                               (plots ? " --plots " + quote(dir / "p") : std::string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("verdict: explained"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(a passive system: no controls)"), std::string::npos) << r.out;
  H5::H5File h5(report.string(), H5F_ACC_RDONLY);
  std::string text;
  const H5::Attribute attribute = h5.openGroup("/").openAttribute("report");
  attribute.read(attribute.getStrType(), text);
  const json j = json::parse(text);
  const json& verdict = j["verdict"];
  ASSERT_EQ(verdict["status"], "explained") << verdict.dump();
  std::vector<std::string> group = {verdict["effect"].get<std::string>()};
  for (const auto& a : verdict["aliases"]) group.push_back(a.get<std::string>());
  const bool damping = std::find(group.begin(), group.end(), "param:swing.damping") != group.end() ||
                       std::find(group.begin(), group.end(), "joint_viscous_damping:swing") != group.end();
  EXPECT_TRUE(damping) << verdict.dump();
  // The damping's own fit in the verdict's group (a much lighter bob with the file's damping is an
  // alias on free-swing data): the field itself, or the added damping b on top of the file's 0.02.
  double b = std::nan("");
  const json& best = j["ranking"][0];
  std::vector<json> fits{best};
  for (const auto& a : best["alias_fits"]) fits.push_back(a);
  for (const json& f : fits) {
    if (f["effect"] == "param:swing.damping") b = f["parameters"]["swing.damping"].get<double>();
    if (f["effect"] == "joint_viscous_damping:swing") b = 0.02 + f["parameters"]["b"].get<double>();
  }
  EXPECT_NEAR(b, 0.3, 0.05) << best.dump();
  for (const auto& entry : j["ranking"]) {
    const std::string name = entry["effect"].get<std::string>();
    EXPECT_NE(name, "input_delay");
    EXPECT_EQ(name.rfind("actuator_gain", 0), std::string::npos) << name;
  }
  // The report's inputs are the states only; the data's controls have no columns.
  hsize_t dims[2] = {0, 0};
  h5.openDataSet("/data/u").getSpace().getSimpleExtentDims(dims);
  EXPECT_EQ(dims[1], 0u);
  EXPECT_TRUE(j["where"]["cross_correlation"]["states"]["swing_dot"].empty()) << j["where"].dump();
  if (plots) {
    for (const char* png : {"free_run.png", "residual_vs_input.png", "ranking.png"})
      EXPECT_GT(fs::file_size(dir / "p" / png), 1000u) << png;
  }
}

TEST(PassiveCli, SolvePlanRolloutAndRunRefuseAPassiveSystem) {
  const fs::path dir = test::temporary_dir("passive_refusals");
  fs::copy_file(pendulum_model(), dir / "pendulum.xml");
  std::ofstream(dir / "solve.toml") << "[system]\nname = \"pendulum.xml\"\ndt = 0.02\n"
                                       "[problem]\nhorizon = 10\nx0 = [0, 0]\ngoal = [0, 0]\nQ = [1, 1]\nR = []\n"
                                       "Qf = [1, 1]\n";
  const std::string model = (dir / "pendulum.xml").string();
  const auto check = [&](const std::string& arguments, const std::string& names) {
    const auto r = test::run_cli(arguments);
    EXPECT_EQ(r.status, 2) << arguments << "\n" << r.err;
    EXPECT_NE(r.err.find("no controls to optimise"), std::string::npos) << arguments << "\n" << r.err;
    EXPECT_NE(r.err.find(names), std::string::npos) << arguments << "\n" << r.err;
    EXPECT_EQ(r.out, "") << arguments;
  };
  check("solve " + quote(dir / "solve.toml"), (dir / "solve.toml").string());
  check("plan " + quote(dir / "solve.toml") + " --data " + quote(dir / "none.csv") + " --out " + quote(dir / "p.h5"),
        model);
  check("rollout --system " + quote(model) + " --policy " + quote(dir / "none.h5") + " --out " + quote(dir / "o.csv"),
        model);
  check("run " + quote(model) + " --out " + quote(dir / "run.h5"), model);
  EXPECT_FALSE(fs::exists(dir / "p.h5"));
  EXPECT_FALSE(fs::exists(dir / "run.h5"));
}

TEST(PassiveCli, APluginSystemWithoutControlsIsSimulatedDiagnosedAndRefusedBySolve) {
  // tests/plugins/passive_plugin.cpp: a pendulum without controls, damping 0 (sim) and 0.2 (real); its
  // entry lists actuator_gain and input_delay, which the registry drops.
  const fs::path dir = test::temporary_dir("passive_plugin");
  const std::string plugin = " --plugin " + quote(fs::path(GPILQG_TEST_PLUGIN_DIR) / "libpassive_plugin.so");
  const fs::path data = dir / "swing.csv";
  const auto sim = test::run_cli("simulate --system passive_pendulum --preset real --episodes 6 --steps 150 --out " +
                                 quote(data) + plugin);
  ASSERT_EQ(sim.status, 0) << sim.err;
  std::ifstream in(data);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "episode,t,theta,theta_dot");
  const auto r = test::run_cli("diagnose --system passive_pendulum --data " + quote(data) + " --json --gp-points 100" +
                               plugin);
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["verdict"]["status"], "explained") << j["verdict"].dump();
  const std::string effect = j["verdict"]["effect"].get<std::string>();
  EXPECT_TRUE(effect == "param:damping" || effect == "joint_viscous_damping:theta") << j["verdict"].dump();
  EXPECT_NEAR(j["verdict"]["parameters"].begin()->get<double>(), 0.2, 0.02) << j["verdict"].dump();
  for (const auto& entry : j["ranking"]) {
    const std::string name = entry["effect"].get<std::string>();
    EXPECT_TRUE(name != "input_delay" && name != "actuator_gain") << name;
  }
  std::ofstream(dir / "solve.toml") << "[system]\nname = \"passive_pendulum\"\ndt = 0.02\n[problem]\nhorizon = 10\n"
                                       "x0 = [0, 0]\ngoal = [0, 0]\nQ = [1, 1]\nR = []\nQf = [1, 1]\n";
  const auto solve = test::run_cli("solve " + quote(dir / "solve.toml") + plugin);
  EXPECT_EQ(solve.status, 2) << solve.err;
  EXPECT_NE(solve.err.find("system passive_pendulum has no controls to optimise"), std::string::npos) << solve.err;
}

TEST(UrdfCli, TheArmsJointsAreControlsAndSimulateAndDiagnoseRun) {
  const fs::path dir = test::temporary_dir("urdf_cli");
  const fs::path data = dir / "arm.csv";
  const auto sim = test::run_cli("simulate --system " + quote(urdf_arm()) +
                                 " --episodes 4 --steps 60 --actuator-noise 0.05 --seed 3 --out " + quote(data));
  ASSERT_EQ(sim.status, 0) << sim.err;
  std::ifstream in(data);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "episode,t,shoulder,elbow,shoulder_dot,elbow_dot,shoulder_motor,elbow_motor");
  // The excitation spans the effort limits, +-8 and +-3 N m.
  double max_shoulder = 0.0, max_elbow = 0.0;
  for (std::string line; std::getline(in, line);) {
    std::vector<double> v;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) v.push_back(std::stod(field));
    max_shoulder = std::max(max_shoulder, std::abs(v[6]));
    max_elbow = std::max(max_elbow, std::abs(v[7]));
  }
  EXPECT_GT(max_shoulder, 4.0);
  EXPECT_LE(max_shoulder, 8.0);
  EXPECT_GT(max_elbow, 1.5);
  EXPECT_LE(max_elbow, 3.0);
  const auto diagnosed =
      test::run_cli("diagnose --system " + quote(urdf_arm()) + " --data " + quote(data) + " --json --gp-points 60");
  ASSERT_EQ(diagnosed.status, 0) << diagnosed.err;
  EXPECT_EQ(json::parse(diagnosed.out)["verdict"]["status"], "consistent") << diagnosed.out;
}

}  // namespace
}  // namespace gpilqg
