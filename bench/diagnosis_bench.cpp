// `gpilqg diagnose --auto` on 2,000 cart-pole transitions with three hidden effects (Coulomb friction
// on the cart, viscous damping on the pole, a constant force): the whole diagnosis, with the command
// line's defaults (GP of 300 points per state, one restart, two threads), the search for several effects
// included. The single-effect diagnosis of the same data (no --auto) is the reference the ratio is taken
// to. And `--auto` on a real-machine-sized log: 25 s of a position-controlled drive at 1 kHz (25,000
// samples, one continuous record; tests/support/ball_drive.hpp), imported from encoder counts. And the
// ranking of every candidate on the inverse-dynamics criterion on the 7-joint arm stand-in
// (tests/support/arm7_log.hpp; 99 of the library's 113, the actuators' gains and gears not being
// candidates there), 5 s and 20 s at 1 kHz, with or without --auto; and --auto on 20 s of the same arm as
// built (link masses off the model's) with biased torque sensors.
//
//   build/bench/gpilqg_diagnosis_bench --benchmark_min_time=1

#include <benchmark/benchmark.h>

#include <map>
#include <stdexcept>
#include <string>

#include "arm7_log.hpp"
#include "ball_drive.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/log_import.hpp"
#include "gpilqg/core/raw_log.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/diagnosis/diagnose_request.hpp"
#include "gpilqg/experiments/import_map.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"
#include "gpilqg/experiments/synthetic_data.hpp"

namespace {

using namespace gpilqg;

/// 10 episodes of 201 samples: 2,000 transitions.
const MeasurementSet& three_hidden_effects() {
  static const MeasurementSet data = [] {
    ModelSpec world;
    world.system = "cartpole";
    for (const auto& [effect, value] :
         {std::pair{"cart_coulomb_friction", 1.5}, std::pair{"pole_viscous_damping", 0.3}, std::pair{"external_force_x", 0.8}})
      world = world.with(find_effect("cartpole", effect), Vector::Constant(1, value));
    ActuatorNoise noise;
    noise.additive_std = Vector::Constant(1, 0.02);
    const DynamicsPtr dynamics = world.build(noise);
    ExcitationSettings settings = default_excitation(*dynamics);
    settings.episodes = 10;
    settings.steps = 201;
    return simulate_measurements(dynamics, settings).set;
  }();
  return data;
}

void diagnose(benchmark::State& state, bool auto_select) {
  diagnosis::DiagnosisOptions options;
  options.model.system = "cartpole";
  options.auto_select = auto_select;
  std::size_t found = 0;
  for (auto _ : state) {
    const diagnosis::DiagnosisReport report = diagnosis::diagnose(three_hidden_effects(), options);
    found = auto_select ? report.verdict.effects.size() : (report.verdict.effect ? 1 : 0);
    benchmark::DoNotOptimize(found);
  }
  if (auto_select && found != 3) throw std::runtime_error("the benchmark's diagnosis did not find the three effects");
  state.counters["effects_found"] = static_cast<double>(found);
  state.counters["transitions"] = 2000;
}

void BM_DiagnoseOneEffect(benchmark::State& state) { diagnose(state, false); }
void BM_DiagnoseAutoThreeEffects(benchmark::State& state) { diagnose(state, true); }

/// The rig's model and its log of `seconds`, imported as `gpilqg data import` does.
std::pair<std::filesystem::path, MeasurementSet> drive_record(const test::DriveRig& rig, double seconds) {
  const auto dir = std::filesystem::temp_directory_path() / "gpilqg_diagnosis_bench";
  std::filesystem::create_directories(dir);
  const auto model = test::drive_model(GPILQG_BENCH_SOURCE_DIR, dir, rig);
  const auto log = test::drive_log(test::drive_world(model, dir, rig), dir, rig, seconds, 3);
  return {model, import_log(read_raw_log(log), read_import_map(test::drive_map(dir)), system_signature(model.string())).set};
}

/// Range 0: samples at 1 kHz; range 1: 0 for the light rig, 1 for the heavy one.
void BM_DiagnoseAutoDrive(benchmark::State& state) {
  const auto rig = state.range(1) == 0 ? test::DriveRig::light() : test::DriveRig::heavy();
  const auto [model, data] = drive_record(rig, static_cast<double>(state.range(0)) / 1000.0);
  diagnosis::DiagnoseRequest request;
  request.system = model.string();
  request.auto_select = true;
  const diagnosis::DiagnosisOptions options = diagnosis::diagnosis_options(request);
  std::size_t found = 0;
  std::string effects;
  for (auto _ : state) {
    const diagnosis::DiagnosisReport report = diagnosis::diagnose(data, options);
    found = report.verdict.effects.size();
    effects.clear();
    for (const std::string& e : report.verdict.effects) effects += " " + e;
    benchmark::DoNotOptimize(found);
  }
  // The drive has three effects (viscous and Coulomb friction, a constant force): the label names what
  // the search chose.
  state.SetLabel("chose" + effects);
  state.counters["effects_found"] = static_cast<double>(found);
  state.counters["samples"] = static_cast<double>(state.range(0));
}

/// The arm's record of `milliseconds` (one sample per millisecond), made once per length and kind:
/// the model with friction, or (`as_built`) the arm as built with friction and torque-sensor offsets.
const test::Arm7Log& arm7_record(long milliseconds, bool as_built = false) {
  static std::map<std::pair<long, bool>, test::Arm7Log> made;
  auto it = made.find({milliseconds, as_built});
  if (it != made.end()) return it->second;
  test::Arm7Options o;
  o.seconds = static_cast<double>(milliseconds) / 1000.0;
  o.seed = 3;
  if (as_built) {
    o.as_built = true;
    o.sensor_offsets = test::arm7_sensor_offsets();
  }
  return made.emplace(std::pair{milliseconds, as_built}, test::arm7_log(GPILQG_BENCH_SOURCE_DIR, o)).first->second;
}

/// The whole diagnosis with the command line's defaults (the criterion chosen by the data: inverse
/// dynamics on this record; the label names it): every candidate ranked (the counter `candidates`),
/// and with --auto the search for several effects (the counter `effects_found`, of which
/// `friction_found` are joint friction, `offsets_found` constant joint torques and `others_found` the
/// rest: body forces, masses, springs, armatures, a delay).
void diagnose_arm7(benchmark::State& state, bool auto_select, bool as_built = false) {
  const test::Arm7Log& log = arm7_record(state.range(0), as_built);
  diagnosis::DiagnoseRequest request;
  request.system = log.model.system;
  request.auto_select = auto_select;
  const diagnosis::DiagnosisOptions options = diagnosis::diagnosis_options(request);
  std::string first, criterion;
  std::size_t candidates = 0, found = 0, friction = 0, offsets = 0;
  for (auto _ : state) {
    const diagnosis::DiagnosisReport report = diagnosis::diagnose(log.measured, options);
    first = report.ranking.empty() ? "none" : report.ranking.front().fit.effect;
    criterion = report.criterion->name();
    candidates = 0;
    for (const auto& entry : report.ranking) candidates += 1 + entry.aliases.size();
    found = report.verdict.effects.size();
    friction = offsets = 0;
    for (const std::string& e : report.verdict.effects) {
      if (e.starts_with("joint_viscous_damping:") || e.starts_with("joint_coulomb_friction:") ||
          e.ends_with(".damping") || e.ends_with(".frictionloss"))
        ++friction;
      else if (e.starts_with("constant_force:"))
        ++offsets;
    }
    benchmark::DoNotOptimize(candidates);
  }
  state.SetLabel(criterion + ", first " + first);
  state.counters["candidates"] = static_cast<double>(candidates);
  state.counters["effects_found"] = static_cast<double>(found);
  if (auto_select) {
    state.counters["friction_found"] = static_cast<double>(friction);
    state.counters["offsets_found"] = static_cast<double>(offsets);
    state.counters["others_found"] = static_cast<double>(found - friction - offsets);
  }
  state.counters["samples"] = static_cast<double>(state.range(0) + 1);
}

void BM_RankArm7InverseDynamics(benchmark::State& state) { diagnose_arm7(state, false); }
void BM_DiagnoseAutoArm7InverseDynamics(benchmark::State& state) { diagnose_arm7(state, true); }
/// The arm as built (masses and a centre of mass off the model's) with biased torque sensors: the
/// friction, the offsets and what else the search adds to the model.
void BM_DiagnoseAutoArm7AsBuilt(benchmark::State& state) { diagnose_arm7(state, true, true); }

BENCHMARK(BM_DiagnoseOneEffect)->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK(BM_DiagnoseAutoThreeEffects)->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK(BM_DiagnoseAutoDrive)->Args({25000, 0})->Args({25000, 1})->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_RankArm7InverseDynamics)->Arg(5000)->Arg(20000)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_DiagnoseAutoArm7InverseDynamics)->Arg(5000)->Arg(20000)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_DiagnoseAutoArm7AsBuilt)->Arg(20000)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
