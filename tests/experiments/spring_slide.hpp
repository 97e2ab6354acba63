#pragma once
/// @file spring_slide.hpp
/// Records of the spring-held carriage of models/spring_slide.xml, for the tests of the effect aliases
/// (effect_alias_test.cpp) and of the Duffing stand-in (duffing_diagnosis_test.cpp). The "real world"
/// is the model file plus hidden effects, stepped by the model's own integrator (MuJoCo's RK4 at its
/// 10 ms timestep, as the diagnosis steps the model), so the only difference between world and model
/// is the hidden effects and the noise.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <random>
#include <string>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/measurements.hpp"
#include "test_support.hpp"

namespace gpilqg::test {

/// tests/experiments/models/spring_slide.xml.
inline std::string spring_slide_model() {
  return (source_dir() / "tests" / "experiments" / "models" / "spring_slide.xml").string();
}

/// The model's carriage mass [kg] and spring stiffness [N/m], as in the file.
inline constexpr double kSlideMass = 1.0;
inline constexpr double kSlideStiffness = 20.0;

/// A random-phase multisine: 8 tones of equal amplitude at 0.2, 0.4, ..., 1.6 Hz (around the carriage's
/// 0.71 Hz), phases fixed per episode, at sample k of step dt. Its RMS over its 5 s period is `rms`
/// (8 tones of amplitude rms / 2); over a few seconds it is close to that.
inline double multisine(int episode, int k, double dt, double rms) {
  double u = 0.0;
  for (int j = 1; j <= 8; ++j) {
    const double phase = std::fmod(1.7 * j * j + 2.3 * episode * j + 0.5 * episode, 2.0 * M_PI);
    u += std::sin(2.0 * M_PI * 0.2 * j * k * dt + phase);
  }
  return rms * u / 2.0;
}

struct SlideRecording {
  int episodes = 6;
  int steps = 300;        ///< samples per episode
  double dt = 0.01;       ///< the sampling step, the model's timestep
  /// The commanded force of episode e at sample k, held over the sample (a DAC's zero-order hold).
  std::function<double(int e, int k)> command;
  double force_noise = 0.0;     ///< std of a white force added to each sample's applied command [N]
  double position_noise = 0.0;  ///< std of the position sensor's noise [m]
  double velocity_noise = 0.0;  ///< std of the velocity sensor's noise [m/s]; unused with estimate_velocity
  /// The velocity is not measured but the central difference of the measured positions (first and
  /// last samples dropped), as from an encoder; the set says so (MeasurementSet::estimated_states).
  bool estimate_velocity = false;
  std::uint64_t seed = 1;
};

/// Records `world` (models/spring_slide.xml with hidden effects) from rest at the origin.
inline MeasurementSet record_slide(const ModelSpec& world, const SlideRecording& s) {
  const DynamicsPtr dynamics = world.build();
  const auto step = make_step_model(dynamics, Integrator::RK4, s.dt, 1);
  const auto workspace = step->make_workspace();
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  MeasurementSet set;
  set.system = dynamics->signature();
  for (int e = 0; e < s.episodes; ++e) {
    Episode raw;
    raw.id = e;
    raw.t = Vector::LinSpaced(s.steps, 0.0, (s.steps - 1) * s.dt);
    raw.x.resize(s.steps, 2);
    raw.u.resize(s.steps, 1);
    Vector x = Vector::Zero(2), next(2), applied(1);
    for (int k = 0; k < s.steps; ++k) {
      raw.u(k, 0) = s.command(e, k);
      raw.x(k, 0) = x(0) + s.position_noise * gauss(rng);
      raw.x(k, 1) = x(1) + s.velocity_noise * gauss(rng);
      applied(0) = raw.u(k, 0) + s.force_noise * gauss(rng);
      step->step(x, applied, next, nullptr, *workspace);
      x = next;
    }
    if (s.estimate_velocity) {
      Episode d;
      d.id = raw.id;
      d.t = raw.t.segment(1, s.steps - 2);
      d.u = raw.u.middleRows(1, s.steps - 2);
      d.x.resize(s.steps - 2, 2);
      for (int k = 1; k + 1 < s.steps; ++k) {
        d.x(k - 1, 0) = raw.x(k, 0);
        d.x(k - 1, 1) = (raw.x(k + 1, 0) - raw.x(k - 1, 0)) / (2.0 * s.dt);
      }
      raw = std::move(d);
    }
    set.episodes.push_back(std::move(raw));
  }
  if (s.estimate_velocity) set.estimated_states = {set.system.states.at(1).name};
  return set;
}

}  // namespace gpilqg::test
