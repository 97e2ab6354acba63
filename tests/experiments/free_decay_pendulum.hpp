#pragma once
/// @file free_decay_pendulum.hpp
/// A lightly damped MuJoCo pendulum in free decay, the passive test case of the simulation criterion
/// (simulation_error_test.cpp) and of its automatic choice (criterion_choice_test.cpp); and a stand-in
/// for a real free-swinging pendulum logged by an encoder at 1 kHz (real_machine_test.cpp).

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/experiments/synthetic_data.hpp"

namespace gpilqg::test {

/// One body on a hinge about y, integrated by RK4 without contacts: the MuJoCo file of both pendulums
/// below. `body` is the body's name and `inertial` its <inertial> attributes.
inline void write_hinge_model(const std::filesystem::path& file, const std::string& model, double timestep,
                              const std::string& body, const std::string& joint, double damping,
                              const std::string& inertial) {
  std::ofstream(file) << "<mujoco model=\"" << model << R"(">
  <compiler angle="radian" inertiafromgeom="false"/>
  <option timestep=")" << timestep << R"(" gravity="0 0 -9.81" integrator="RK4"><flag contact="disable"/></option>
  <worldbody>
    <body name=")" << body << R"(">
      <joint name=")" << joint << R"(" type="hinge" axis="0 1 0" damping=")" << damping << R"("/>
      <inertial )" << inertial << R"(/>
    </body>
  </worldbody>
</mujoco>
)";
}

/// A point-like bob of 1 kg on a 0.25 m rod about a hinge: I = 0.0626 kg m^2, omega_0 = 6.26 rad/s
/// (period 1.0 s); damping b gives zeta = b / (2 I omega_0), 0.005 for b = 0.0039 N m s/rad.
inline void write_pendulum(const std::filesystem::path& file, double damping) {
  write_hinge_model(file, "pendulum", 0.01, "bob", "hinge", damping,
                    R"(pos="0 0 -0.25" mass="1" diaginertia="0.0001 0.0001 0.0001")");
}

/// The pendulum's moment of inertia about the hinge [kg m^2] and its weight's lever: m g l [N m].
inline constexpr double kPendulumInertia = 1.0 * 0.25 * 0.25 + 0.0001;
inline constexpr double kPendulumGravityTorque = 1.0 * 9.81 * 0.25;

inline constexpr double kPendulumDamping = 0.0039;
inline constexpr double kPendulumAngleNoise = 1e-3;  // rad

/// Free decay of the pendulum of `world_file`: `episodes` records of 4 s (about 4 periods) at 100 Hz
/// from angles of 0.3 to 0.9 rad, no controls. The angle carries sensor noise of 1 mrad; the velocity
/// is not measured but computed from the noisy angles by central differences (first and last sample
/// dropped), as from an encoder.
inline MeasurementSet free_decay(const std::filesystem::path& world_file, int episodes, std::uint64_t seed) {
  ModelSpec world;
  world.system = world_file.string();
  ExcitationSettings s;
  s.episodes = episodes;
  s.steps = 402;
  s.dt = 0.01;
  s.nominal_state = Vector::Zero(2);
  s.nominal_state(0) = 0.6;
  s.initial_spread = Vector::Zero(2);
  s.initial_spread << 0.3, 0.5;
  s.observation_std = Vector::Zero(2);
  s.observation_std(0) = kPendulumAngleNoise;
  s.seed = seed;
  MeasurementSet set = simulate_measurements(world.build(), s).set;
  for (Episode& e : set.episodes) {
    const int T = e.length();
    Episode d;
    d.id = e.id;
    d.t = e.t.segment(1, T - 2);
    d.u = e.u.middleRows(1, T - 2);
    d.x.resize(T - 2, 2);
    for (int k = 1; k + 1 < T; ++k) {
      d.x(k - 1, 0) = e.x(k, 0);
      d.x(k - 1, 1) = (e.x(k + 1, 0) - e.x(k - 1, 0)) / (2.0 * s.dt);
    }
    e = std::move(d);
  }
  return set;
}

/// A rod pendulum of a teaching lab, logged at 1 kHz: 0.2 kg with its centre of mass 0.15 m below the
/// hinge, I = 0.0015 + 0.2 * 0.15^2 = 0.006 kg m^2 about it, omega_0 = sqrt(m g l / I) = 7.0 rad/s
/// (period 0.90 s at small angles). A bearing damping b gives zeta = b / (2 I omega_0): 0.0027 for the
/// b = 2.24e-4 N m s/rad of kRodDamping, an amplitude that falls by a third in 20 s. `damping` 0 is the
/// user's model: the rod without its bearing's losses.
inline void write_rod_pendulum(const std::filesystem::path& file, double damping) {
  write_hinge_model(file, "rod_pendulum", 0.001, "rod", "swing", damping,
                    R"(pos="0 0 -0.15" mass="0.2" diaginertia="0.0015 0.0015 0.00001")");
}

inline constexpr double kRodDamping = 2.24e-4;  // N m s/rad

/// A free swing of the rod pendulum of `world_file` released from rest at `release` rad, `seconds`
/// long at 1 kHz, as an encoder of `counts` per turn logs it: a CSV file with the columns time [s]
/// and angle [rad], each angle rounded to the encoder's step 2 pi / counts, and no velocity (the
/// import estimates it).
inline void write_encoder_swing(const std::filesystem::path& world_file, const std::filesystem::path& csv,
                                double release, double seconds, int counts) {
  ModelSpec world;
  world.system = world_file.string();
  ExcitationSettings s;
  s.episodes = 1;
  s.steps = static_cast<int>(std::lround(seconds / 0.001));
  s.dt = 0.001;
  s.nominal_state = Vector::Zero(2);
  s.nominal_state(0) = release;
  s.initial_spread = Vector::Zero(2);
  s.observation_std = Vector::Zero(2);
  const Episode e = simulate_measurements(world.build(), s).set.episodes.front();
  const double step = 2.0 * M_PI / counts;
  std::ofstream out(csv);
  out << "time,angle\n";
  for (int k = 0; k < e.length(); ++k) {
    char line[64];
    std::snprintf(line, sizeof line, "%.3f,%.10g\n", e.t(k), step * std::round(e.x(k, 0) / step));
    out << line;
  }
}

}  // namespace gpilqg::test
