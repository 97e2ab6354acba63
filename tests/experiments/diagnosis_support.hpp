#pragma once
// Measurement sets with one hidden effect, for the diagnosis tests: the "real world" is the simulator
// preset plus the effect, simulated with noise by simulate_measurements (RK4, 10 sub-steps).

#include <cstdint>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"
#include "gpilqg/experiments/synthetic_data.hpp"

namespace gpilqg::test {

/// Small data sets keep the tests fast: 7 episodes of 120 samples (cart-pole) or 8 of 70 (quadrotor),
/// observation noise 1e-3 on every state (default_excitation), additive actuator noise.
inline MeasurementSet hidden_effect_data(const DynamicsPtr& world, std::uint64_t seed) {
  ExcitationSettings settings = default_excitation(*world);
  if (world->name() == "cartpole") {
    settings.episodes = 7;
    settings.steps = 120;
  } else {
    settings.episodes = 8;
    settings.steps = 70;
  }
  settings.seed = seed;
  return simulate_measurements(world, settings).set;
}

inline ActuatorNoise actuator_noise(int controls, double std) {
  ActuatorNoise noise;
  noise.additive_std = Vector::Constant(controls, std);
  return noise;
}

/// Diagnosis options for tests: small GPs without restarts, one thread.
inline diagnosis::DiagnosisOptions fast_options(const std::string& system) {
  diagnosis::DiagnosisOptions o;
  o.model.system = system;
  o.gp.points = system == "cartpole" ? 100 : 60;
  o.gp.restarts = 0;
  o.gp.threads = 1;
  return o;
}

}  // namespace gpilqg::test
