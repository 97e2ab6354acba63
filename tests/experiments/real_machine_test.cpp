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

#include "ball_drive.hpp"
#include "diagnosis_support.hpp"
#include "free_decay_pendulum.hpp"
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

/// A rig's files as a user has them: its model, the world (the model with the rig's truth), and
/// `records` (1 or 2) records imported by `gpilqg data import` (the second a new trajectory of the same
/// machine, running when its record begins; the first begins as `first_start` says).
struct DriveFiles {
  std::string model, world, first, second;
};

DriveFiles drive_files(const test::DriveRig& rig, const std::filesystem::path& dir, double seconds, int records,
                       test::DriveStart first_start = test::DriveStart::Tracking,
                       test::DriveMotion motion = test::DriveMotion::Sines) {
  DriveFiles files;
  const auto model = test::drive_model(test::source_dir(), dir, rig);
  const auto world = test::drive_world(model, dir, rig);
  const auto map = test::drive_map(dir);
  files.model = "'" + model.string() + "'";
  files.world = "'" + world.string() + "'";
  for (int record = 0; record < records; ++record) {
    const auto log = test::drive_log(world, dir, rig, seconds, 3 + static_cast<std::uint64_t>(record), record,
                                     record == 0 ? first_start : test::DriveStart::Tracking, motion);
    const auto out = dir / fmt::format("drive_{}.h5", record);
    const auto r = test::run_cli("data import '" + log.string() + "' --system " + files.model + " --map '" + map.string() +
                                 "' --out '" + out.string() + "'");
    if (r.status != 0) throw std::runtime_error("data import: " + r.err);
    (record == 0 ? files.first : files.second) = "'" + out.string() + "'";
  }
  return files;
}

/// `gpilqg diagnose <arguments> --json`, parsed; throws with the command's stderr when it fails.
nlohmann::json diagnose_json(const std::string& arguments) {
  const auto r = test::run_cli("diagnose " + arguments + " --json");
  if (r.status != 0) throw std::runtime_error("diagnose " + arguments + ": " + r.err);
  return nlohmann::json::parse(r.out);
}

std::string found_text(const std::map<std::string, double>& values) {
  std::string found;
  for (const auto& [name, value] : values) found += fmt::format(" {}={:.4g}", name, value);
  return found;
}

constexpr std::initializer_list<const char*> kViscous = {"joint_viscous_damping:slide", "param:slide.damping"};
constexpr std::initializer_list<const char*> kCoulomb = {"joint_coulomb_friction:slide", "param:slide.frictionloss"};
constexpr std::initializer_list<const char*> kConstant = {"constant_force:slide", "external_force_x:carriage"};

/// No proxy for the friction: no actuator gain, and an inertia only as a recalibration of the rig's
/// own (a mass within 1% of the rig's, an armature below 1% of it), never a new inertia that stands in
/// for a force.
void expect_no_proxy(const std::map<std::string, double>& values, const test::DriveRig& rig) {
  for (const char* proxy : {"actuator_gain:drive", "param:drive.gear"})
    EXPECT_EQ(values.count(proxy), 0u) << proxy << " was chosen:" << found_text(values);
  if (values.count("param:carriage.mass") != 0) {
    EXPECT_NEAR(values.at("param:carriage.mass"), rig.mass, 0.01 * rig.mass) << found_text(values);
  }
  if (values.count("param:slide.armature") != 0) {
    EXPECT_LT(std::abs(values.at("param:slide.armature")), 0.01 * rig.mass) << found_text(values);
  }
}

/// The heavy drive's three effects as the defaults must name them: viscous friction within 5%, Coulomb
/// within 10%, the constant within 35% (1.5% of the force the loop applies), and no proxy.
void expect_heavy_drive_frictions(const std::map<std::string, double>& values, const test::DriveRig& rig) {
  const test::DriveTruth& truth = rig.truth;
  EXPECT_NEAR(chosen(values, kViscous), truth.damping, 0.05 * truth.damping) << found_text(values);
  EXPECT_NEAR(chosen(values, kCoulomb), truth.friction, 0.1 * truth.friction) << found_text(values);
  EXPECT_NEAR(chosen(values, kConstant), truth.constant, 0.35 * std::abs(truth.constant)) << found_text(values);
  expect_no_proxy(values, rig);
}

// A position-controlled drive at 1 kHz, as real drives are logged (ball_drive.hpp): a PD loop on an
// encoder of 1 um, positions and the motor force only, one continuous record of 12 s. The world has
// viscous friction, Coulomb friction (MuJoCo's frictionloss) and a constant force together; the model
// has none of them. --auto must find all three, and no proxy (a gain; an inertia only within 1% of
// the rig's).
TEST(RealMachineCli, ClosedLoopDriveAtOneKilohertzFindsItsThreeFrictionTerms) {
  const auto rig = test::DriveRig::light();
  const auto files = drive_files(rig, test::temporary_dir("ball_drive"), 12.0, 1);
  const nlohmann::json report = diagnose_json("--system " + files.model + " --data " + files.first + " --auto");
  ASSERT_FALSE(report["heldout_blocks"].is_null());  // one record: held-out blocks
  const auto values = chosen_values(report);
  const test::DriveTruth& truth = rig.truth;
  EXPECT_NEAR(chosen(values, kViscous), truth.damping, 0.15 * truth.damping) << found_text(values);
  EXPECT_NEAR(chosen(values, kCoulomb), truth.friction, 0.2 * truth.friction) << found_text(values);
  EXPECT_NEAR(chosen(values, kConstant), truth.constant, 0.35 * truth.constant) << found_text(values);
  expect_no_proxy(values, rig);
}

// The same loop on the scale of an industrial ball-screw axis: 95 kg commanded in volts through a motor
// constant of 35 N/V, viscous friction 200 N s/m, Coulomb 20 N, a constant -3 N, one record of 25 s
// that begins with the carriage at rest 4 cm from the reference (the loop's step response, some 6 kN
// in the first sample, as a record started with the machine does). The velocity is estimated by
// the import and the commands are generalised forces sampled fast against the motion, so the defaults
// take the inverse-dynamics criterion in its instrumental-variable form, as drives are identified
// (IDIM-IV), on the positions differentiated twice (accelerations.hpp). With the defaults the
// diagnosis must name the three effects (viscous within 5%, Coulomb within 10%, the constant within
// 35%: it is 1.5% of the force the loop applies), add no proxy, and its written model must leave on a second record (a new trajectory) a
// held-out force residual within 2% of the world's own.
TEST(RealMachineCli, HeavyDriveWithEstimatedVelocitiesTakesInverseDynamicsAndPredictsASecondRecord) {
  const auto rig = test::DriveRig::heavy();
  const auto dir = test::temporary_dir("heavy_drive");
  const auto files = drive_files(rig, dir, 25.0, 2, test::DriveStart::AtRest);
  const std::string written = "'" + (dir / "diagnosed.toml").string() + "'";
  const nlohmann::json report =
      diagnose_json("--system " + files.model + " --data " + files.first + " --auto --write-model " + written);
  EXPECT_EQ(report["criterion"]["name"], "inverse-dynamics-iv") << report["criterion"].dump();
  EXPECT_NE(report["criterion"]["reason"].get<std::string>().find("on the measured positions"), std::string::npos)
      << report["criterion"].dump();
  const auto values = chosen_values(report);
  expect_heavy_drive_frictions(values, rig);

  // The second record, scored by the diagnosis of each model: the same criterion, the same blocks.
  const nlohmann::json by_world = diagnose_json("--system " + files.world + " --data " + files.second);
  const nlohmann::json by_model =
      diagnose_json("--system " + files.model + " --model " + written + " --data " + files.second);
  const double world_rmse = by_world["ranking"][0]["heldout_rmse_before"].get<double>();
  const double model_rmse = by_model["ranking"][0]["heldout_rmse_before"].get<double>();
  std::printf("heavy drive, second record: held-out force rmse %.4g N (world) and %.4g N (diagnosed)%s\n", world_rmse,
              model_rmse, found_text(values).c_str());
  EXPECT_LE(model_rmse, 1.02 * world_rmse);
}

// The heavy drive on point-to-point moves (ball_drive.hpp point_to_point: 2 m/s^2 up to 0.25 m/s between
// random positions), at rest for 0.2 to 0.6 s between them, as drives are often excited: some 40% of
// the record at standstill, where MuJoCo's dry friction (a soft constraint) lets the carriage creep by
// an encoder count or two while the loop balances the constant force. A friction model's force there
// turns with velocities far below what the estimate resolves, so the inverse-dynamics criterion leaves
// those rows out (accelerations.hpp, standstill_rows). With the defaults the diagnosis must leave out
// at least a fifth of the rows, name the three effects as closely as on the sines, add no proxy, and
// predict a second record of such moves within 2% of the world's own residual.
TEST(RealMachineCli, HeavyDriveAtRestBetweenMovesLeavesTheStandstillOutAndFindsItsConstant) {
  const auto rig = test::DriveRig::heavy();
  const auto dir = test::temporary_dir("moves_drive");
  const auto files = drive_files(rig, dir, 25.0, 2, test::DriveStart::Tracking, test::DriveMotion::PointToPoint);
  const std::string written = "'" + (dir / "diagnosed.toml").string() + "'";
  const nlohmann::json report =
      diagnose_json("--system " + files.model + " --data " + files.first + " --auto --write-model " + written);
  EXPECT_EQ(report["criterion"]["name"], "inverse-dynamics-iv") << report["criterion"].dump();
  const nlohmann::json& weights = report["criterion"]["weights"];
  ASSERT_EQ(weights.size(), 1u) << report["criterion"].dump();
  EXPECT_GT(weights[0]["standstill_rows"].get<long>(), report["samples"].get<long>() / 5) << weights.dump();
  const auto values = chosen_values(report);
  expect_heavy_drive_frictions(values, rig);
  EXPECT_EQ(values.size(), 3u) << found_text(values);

  const nlohmann::json by_world = diagnose_json("--system " + files.world + " --data " + files.second);
  const nlohmann::json by_model =
      diagnose_json("--system " + files.model + " --model " + written + " --data " + files.second);
  const double world_rmse = by_world["ranking"][0]["heldout_rmse_before"].get<double>();
  const double model_rmse = by_model["ranking"][0]["heldout_rmse_before"].get<double>();
  std::printf("heavy drive between moves, second record: held-out force rmse %.4g N (world) and %.4g N (diagnosed)%s\n",
              world_rmse, model_rmse, found_text(values).c_str());
  EXPECT_LE(model_rmse, 1.02 * world_rmse);
}

// A free-swinging rod pendulum as a lab logs it (free_decay_pendulum.hpp): released from rest at 0.8 rad,
// 20 s at 1 kHz, angles from an encoder of 4096 counts a turn (a step of 1.5 mrad), no velocity. The
// user's model is the rod without its bearing; the world has a viscous damping of 2.24e-4 N m s/rad
// (zeta 0.0027). `data import` estimates the velocity, then `diagnose --auto --write-model` with the
// defaults must take the simulation criterion (a passive system), name the damping within 5% and nothing
// else, and its written model must leave on a second swing (released at 0.5 rad) a held-out error
// within 2% of the world's own.
TEST(RealMachineCli, FreeSwingingPendulumLoggedByAnEncoderFindsItsBearingDamping) {
  const auto dir = test::temporary_dir("encoder_pendulum");
  const auto model = dir / "rod.xml", world = dir / "rod_world.xml", map = dir / "map.toml";
  test::write_rod_pendulum(model, 0.0);
  test::write_rod_pendulum(world, test::kRodDamping);
  std::ofstream(map) << "[time]\ncolumn = \"time\"\n[states]\nswing = \"angle\"\n[velocities]\nmethod = \"savitzky_golay\"\n";
  std::string records[2];
  for (int k = 0; k < 2; ++k) {
    const auto csv = dir / fmt::format("swing_{}.csv", k), h5 = dir / fmt::format("swing_{}.h5", k);
    test::write_encoder_swing(world, csv, k == 0 ? 0.8 : 0.5, k == 0 ? 20.0 : 10.0, 4096);
    const auto r = test::run_cli("data import '" + csv.string() + "' --system '" + model.string() + "' --map '" +
                                 map.string() + "' --out '" + h5.string() + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    records[k] = "'" + h5.string() + "'";
  }
  const std::string written = "'" + (dir / "diagnosed.toml").string() + "'";
  const nlohmann::json report =
      diagnose_json("--system '" + model.string() + "' --data " + records[0] + " --auto --write-model " + written);
  EXPECT_EQ(report["criterion"]["name"], "simulation") << report["criterion"].dump();
  const auto values = chosen_values(report);
  EXPECT_EQ(values.size(), 1u) << found_text(values);
  EXPECT_NEAR(chosen(values, {"joint_viscous_damping:swing", "param:swing.damping"}), test::kRodDamping,
              0.05 * test::kRodDamping)
      << found_text(values);

  const nlohmann::json by_world = diagnose_json("--system '" + world.string() + "' --data " + records[1]);
  const nlohmann::json by_model =
      diagnose_json("--system '" + model.string() + "' --model " + written + " --data " + records[1]);
  // The angle is what the encoder measured; the velocity's error is the derivative filter's noise.
  const double world_rmse = by_world["ranking"][0]["heldout_rmse_by_state"]["before"]["swing"].get<double>();
  const double model_rmse = by_model["ranking"][0]["heldout_rmse_by_state"]["before"]["swing"].get<double>();
  std::printf("encoder pendulum, second swing: held-out angle rmse %.4g rad (world) and %.4g rad (diagnosed)%s\n", world_rmse,
              model_rmse, found_text(values).c_str());
  EXPECT_LE(model_rmse, 1.02 * world_rmse);
}

}  // namespace
}  // namespace gpilqg
