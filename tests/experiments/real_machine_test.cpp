// Diagnosis on data that look like real machines, made with MuJoCo and not with the effect library:
// effects on their own scales (a carriage at 0.01 m/s), MuJoCo's frictionloss (a constraint, a true
// sign function) where the library has a smoothed Coulomb term.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <random>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "gpilqg/core/integrator.hpp"

#include "diagnosis_support.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

std::string slow_slide() { return (test::source_dir() / "tests" / "experiments" / "models" / "slow_slide.xml").string(); }

/// The carriage with a frictionloss of `friction` N, excited by forces of up to +-2.5 N held 50 ms:
/// 8 episodes of 2 s at 100 Hz, sensor noise 1e-5 m and 2e-4 m/s (2% of the typical speed).
MeasurementSet slow_slide_data(double friction, std::uint64_t seed) {
  const DynamicsPtr world = find_system(slow_slide())->build(Preset::RealWorld, {{"slide.frictionloss", friction}}, {});
  ExcitationSettings settings = default_excitation(*world);
  settings.episodes = 8;
  settings.steps = 200;
  settings.dt = 0.01;
  settings.control_amplitude = Vector::Constant(1, 2.5);
  settings.observation_std = Vector(2);
  settings.observation_std << 1e-5, 2e-4;
  settings.seed = seed;
  return simulate_measurements(world, settings).set;
}

/// The fitted value of `effect` in the ranking (its group's best or an alias); NaN when absent.
double ranked_value(const diagnosis::DiagnosisReport& r, const std::string& effect) {
  for (const auto& group : r.ranking) {
    if (group.fit.effect == effect) return group.fit.estimate(0);
    for (const auto& a : group.aliases)
      if (a.effect == effect) return a.estimate(0);
  }
  return std::nan("");
}

TEST(RealMachine, SlowSlideCoulombFrictionOnTheDataScale) {
  const double friction = 1.0;
  const MeasurementSet data = slow_slide_data(friction, 5);
  diagnosis::DiagnosisOptions o = test::fast_options(slow_slide());
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, o);
  ASSERT_NE(r.verdict.status, "consistent") << r.verdict.reason;
  ASSERT_TRUE(r.verdict.effect.has_value()) << r.verdict.reason;
  // MuJoCo's own frictionloss or the library's Coulomb friction: either is the truth.
  const std::string& named = r.verdict.effect->effect;
  EXPECT_TRUE(named == "joint_coulomb_friction:slide" || named == "param:slide.frictionloss") << named;
  // The library's Coulomb term, smoothed over v0 from the data's speeds, within 20%.
  const double coulomb = ranked_value(r, "joint_coulomb_friction:slide");
  EXPECT_NEAR(coulomb, friction, 0.2 * friction);
  // v0 is a twentieth of the RMS speed (about 0.01 m/s here), not the 0.05 m/s of the library's
  // default, which would make the friction a viscous term at these speeds and miss its value.
  const double v0 = r.model_before.smoothing.at("joint_coulomb_friction:slide");
  EXPECT_GT(v0, 1e-4);
  EXPECT_LT(v0, 2e-3);
  o.model.smoothing["joint_coulomb_friction:slide"] = 0.05;
  o.auto_select = false;
  const diagnosis::DiagnosisReport at_default = diagnosis::diagnose(data, o);
  EXPECT_GT(std::abs(ranked_value(at_default, "joint_coulomb_friction:slide") - friction), 0.3 * friction);
}

// A position-controlled drive at 1 kHz, as real drives are logged: a PD loop on an encoder of 1 um,
// positions and the motor force only, one continuous record. The world has viscous friction (MuJoCo's
// joint damping), Coulomb friction (frictionloss) and a constant force (gravity along a tilted axis)
// together; the model has none of them.
struct DriveTruth {
  double damping = 30.0;      ///< N s/m
  double friction = 5.0;      ///< N
  double constant = 3.0;      ///< N: mass 2 kg times a gravity of 1.5 m/s^2 along the slide
};

std::filesystem::path drive_model() { return test::source_dir() / "tests" / "experiments" / "models" / "ball_drive.xml"; }

/// The world: ball_drive.xml with the three effects written into the file.
std::filesystem::path drive_world(const std::filesystem::path& dir, const DriveTruth& truth) {
  std::ifstream in(drive_model());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  };
  replace(R"(<option timestep="0.001"/>)",
          fmt::format(R"(<option timestep="0.001" gravity="{} 0 -9.81"/>)", truth.constant / 2.0));
  replace(R"(<joint name="slide" type="slide" axis="1 0 0"/>)",
          fmt::format(R"(<joint name="slide" type="slide" axis="1 0 0" damping="{}" frictionloss="{}"/>)", truth.damping,
                      truth.friction));
  const auto file = dir / "ball_drive_world.xml";
  std::ofstream(file) << text;
  return file;
}

/// `seconds` of the PD loop at 1 kHz tracking a sum of three sines (5, 3 and 2 cm at 0.5, 1.3 and
/// 2.9 Hz), with force noise of 0.3 N on the motor; the log holds the encoder's count in um and the
/// commanded force, as a CSV with the columns t, encoder_mm (to the count), force_N.
std::filesystem::path drive_log(const std::filesystem::path& world_file, const std::filesystem::path& dir, double seconds,
                                std::uint64_t seed) {
  const DynamicsPtr world = find_system(world_file.string())->build(Preset::Simulator, {}, {});
  const double dt = 1e-3, kp = 3000.0, kd = 60.0, count = 1e-6;
  const auto step = make_step_model(world, Integrator::RK4, dt, 4);
  std::mt19937_64 random(seed);
  std::normal_distribution<double> force_noise(0.0, 0.3);
  Vector x = Vector::Zero(2), next(2);
  double previous = 0.0;
  const auto file = dir / "drive_log.csv";
  std::ofstream out(file);
  out << "t,encoder_mm,force_N\n";
  const long samples = std::lround(seconds / dt);
  for (long k = 0; k <= samples; ++k) {
    const double t = static_cast<double>(k) * dt;
    const double reference = 0.05 * std::sin(2 * M_PI * 0.5 * t) + 0.03 * std::sin(2 * M_PI * 1.3 * t + 1.0) +
                             0.02 * std::sin(2 * M_PI * 2.9 * t + 2.0);
    const double encoder = std::round(x(0) / count) * count;
    const double speed = k == 0 ? 0.0 : (encoder - previous) / dt;
    previous = encoder;
    const double force = kp * (reference - encoder) - kd * speed;
    out << fmt::format("{:.3f},{:.3f},{:.6f}\n", t, encoder * 1e3, force);
    step->step(x, Vector::Constant(1, force + force_noise(random)), next);
    x = next;
  }
  return file;
}

/// The last --auto step's joint values: effect -> its first parameter.
std::map<std::string, double> chosen_values(const nlohmann::json& report) {
  std::map<std::string, double> out;
  const auto& steps = report["selection"]["steps"];
  if (steps.empty()) return out;
  const auto& last = steps.back();
  out[last["effect"].get<std::string>()] = last["parameters"].begin().value().get<double>();
  for (const auto& v : last["refitted"]) out[v["effect"].get<std::string>()] = v["parameters"].begin().value().get<double>();
  return out;
}

/// The value of whichever of `names` (the same physics under different names) was chosen; NaN if none.
double chosen(const std::map<std::string, double>& values, std::initializer_list<const char*> names) {
  for (const char* name : names)
    if (auto it = values.find(name); it != values.end()) return it->second;
  return std::nan("");
}

TEST(RealMachine, ClosedLoopDriveAtOneKilohertzFindsItsThreeFrictionTerms) {
  const DriveTruth truth;
  const auto dir = test::temporary_dir("ball_drive");
  const auto log = drive_log(drive_world(dir, truth), dir, 12.0, 3);
  std::ofstream(dir / "map.toml") << "[time]\ncolumn = \"t\"\n\n[states]\nslide = { column = \"encoder_mm\", unit = \"mm\" }\n\n"
                                     "[controls]\ndrive = \"force_N\"\n\n[velocities]\nmethod = \"savitzky_golay\"\nwindow = 21\norder = 2\n";
  const std::string model = "'" + drive_model().string() + "'";
  const auto imported = test::run_cli("data import '" + log.string() + "' --system " + model + " --map '" +
                                      (dir / "map.toml").string() + "' --out '" + (dir / "drive.h5").string() + "'");
  ASSERT_EQ(imported.status, 0) << imported.err;
  const auto r = test::run_cli("diagnose --system " + model + " --data '" + (dir / "drive.h5").string() + "' --auto --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  ASSERT_FALSE(report["heldout_blocks"].is_null());  // one record: held-out blocks
  const auto values = chosen_values(report);
  std::string found;
  for (const auto& [name, value] : values) found += fmt::format(" {}={:.4g}", name, value);
  EXPECT_NEAR(chosen(values, {"joint_viscous_damping:slide", "param:slide.damping"}), truth.damping, 0.15 * truth.damping)
      << found;
  EXPECT_NEAR(chosen(values, {"joint_coulomb_friction:slide", "param:slide.frictionloss"}), truth.friction,
              0.2 * truth.friction)
      << found;
  EXPECT_NEAR(chosen(values, {"constant_force:slide", "external_force_x:carriage"}), truth.constant, 0.35 * truth.constant)
      << found;
  for (const char* proxy : {"actuator_gain:drive", "param:drive.gear", "param:carriage.mass"})
    EXPECT_EQ(values.count(proxy), 0u) << proxy << " was chosen:" << found;
}

}  // namespace
}  // namespace gpilqg
