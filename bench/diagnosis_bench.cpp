// `gpilqg diagnose --auto` on 2,000 cart-pole transitions with three hidden effects (Coulomb friction
// on the cart, viscous damping on the pole, a constant force): the whole diagnosis, with the command
// line's defaults (GP of 300 points per state, one restart, two threads), forward selection included.
// The single-effect diagnosis of the same data (no --auto) is the reference the ratio is taken to.
//
//   build/bench/gpilqg_diagnosis_bench --benchmark_min_time=1

#include <benchmark/benchmark.h>

#include <stdexcept>

#include "gpilqg/core/effect_library.hpp"
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
    found = report.selection ? report.selection->steps.size() : (report.verdict.effect ? 1 : 0);
    benchmark::DoNotOptimize(found);
  }
  if (auto_select && found != 3) throw std::runtime_error("the benchmark's diagnosis did not find the three effects");
  state.counters["effects_found"] = static_cast<double>(found);
  state.counters["transitions"] = 2000;
}

void BM_DiagnoseOneEffect(benchmark::State& state) { diagnose(state, false); }
void BM_DiagnoseAutoThreeEffects(benchmark::State& state) { diagnose(state, true); }

BENCHMARK(BM_DiagnoseOneEffect)->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK(BM_DiagnoseAutoThreeEffects)->Unit(benchmark::kSecond)->Iterations(3);

}  // namespace
