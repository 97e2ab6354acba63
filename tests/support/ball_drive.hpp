#pragma once
/// @file ball_drive.hpp
/// A position-controlled drive logged as real drives are: tests/experiments/models/ball_drive.xml (a
/// carriage on a slide, driven by a motor) in a PD loop at 1 kHz on an encoder of 1 um, the log holding
/// the encoder's position and the motor command only, one continuous record. Two rigs: a light one
/// (2 kg, the command in newtons) and a heavy one on the scale of an industrial ball-screw axis (95 kg,
/// the command in volts through a motor constant of 35 N/V, friction of hundreds of N s/m). The "real"
/// drive is the rig's model with viscous friction (MuJoCo's joint damping), Coulomb friction (its
/// frictionloss, a constraint) and a constant force (gravity along a tilted axis) written in: none of
/// them is made by the effect library. For the diagnosis tests and benchmark; throws std::runtime_error
/// when a file cannot be written or read.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/system_registry.hpp"

namespace gpilqg::test {

/// The effects the model lacks, in N s/m and N.
struct DriveTruth {
  double damping = 30.0;   ///< N s/m
  double friction = 5.0;   ///< N
  double constant = 3.0;   ///< N: along the slide (gravity along a tilted axis)
};

/// What the model knows (mass, motor constant) and how the rig is run. The PD gains and the force noise
/// scale with the mass, so both rigs track with the same bandwidth (39 rad/s) and the same relative noise.
struct DriveRig {
  double mass = 2.0;         ///< kg
  double gear = 1.0;         ///< N per unit of command
  double force_noise = 0.3;  ///< N, white on the motor at every sample
  DriveTruth truth{};

  double kp() const { return 1500.0 * mass; }  ///< N/m
  double kd() const { return 30.0 * mass; }    ///< N s/m on the encoder's difference quotient

  /// 2 kg, commanded in newtons: viscous 30 N s/m, Coulomb 5 N, a constant 3 N.
  static DriveRig light() { return {}; }
  /// 95 kg, commanded in volts at 35 N/V: viscous 200 N s/m, Coulomb 20 N, a constant -3 N (the scale of
  /// an industrial ball-screw axis; round values, not any one machine's).
  static DriveRig heavy() { return {95.0, 35.0, 14.0, {200.0, 20.0, -3.0}}; }
};

inline std::string drive_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("ball_drive.xml: no '" + from + "'");
  text.replace(at, from.size(), to);
}

/// The rig's model (tests/experiments/models/ball_drive.xml with its mass and motor constant), in `dir`.
inline std::filesystem::path drive_model(const std::filesystem::path& source_dir, const std::filesystem::path& dir,
                                         const DriveRig& rig) {
  std::string text = drive_text(source_dir / "tests" / "experiments" / "models" / "ball_drive.xml");
  replace_once(text, R"(mass="2")", fmt::format(R"(mass="{}")", rig.mass));
  replace_once(text, R"(gear="1")", fmt::format(R"(gear="{}")", rig.gear));
  const auto file = dir / "ball_drive.xml";
  std::ofstream out(file);
  if (!(out << text)) throw std::runtime_error("cannot write " + file.string());
  return file;
}

/// The world: the rig's `model` with the three effects of its truth written into the file, in `dir`.
inline std::filesystem::path drive_world(const std::filesystem::path& model, const std::filesystem::path& dir,
                                         const DriveRig& rig) {
  std::string text = drive_text(model);
  const DriveTruth& truth = rig.truth;
  replace_once(text, R"(<option timestep="0.001"/>)",
               fmt::format(R"(<option timestep="0.001" gravity="{} 0 -9.81"/>)", truth.constant / rig.mass));
  replace_once(text, R"(<joint name="slide" type="slide" axis="1 0 0"/>)",
               fmt::format(R"(<joint name="slide" type="slide" axis="1 0 0" damping="{}" frictionloss="{}"/>)",
                           truth.damping, truth.friction));
  const auto file = dir / "ball_drive_world.xml";
  std::ofstream(file) << text;
  return file;
}

/// How a record begins.
enum class DriveStart {
  Tracking,  ///< the carriage on the reference, moving with it: a record of a running machine
  AtRest,    ///< the carriage at rest at 0 while the reference is not: the loop's step response first
};

/// What the loop tracks.
enum class DriveMotion {
  Sines,         ///< a sum of three sines: the carriage never rests
  PointToPoint,  ///< moves between random positions, the carriage at rest between them (point_to_point)
};

/// A point-to-point reference, its position and rate at `samples` + 1 samples of step `dt`: from 0, a
/// standstill of 0.2 to 0.6 s, then a move to a random position in [0, 0.15] m at 2 m/s^2 up to 0.25 m/s
/// (whole samples of constant acceleration, so that each move ends at rest), and again.
inline std::pair<std::vector<double>, std::vector<double>> point_to_point(long samples, double dt,
                                                                          std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> target(0.0, 0.15), standstill(0.2, 0.6);
  const double speed = 0.25, acceleration = 2.0;
  std::vector<double> position, rate;
  double p = 0.0, v = 0.0;
  const auto push = [&](double a) {
    position.push_back(p);
    rate.push_back(v);
    p += v * dt + 0.5 * a * dt * dt;
    v += a * dt;
  };
  while (static_cast<long>(position.size()) <= samples) {
    for (long n = std::lround(standstill(random) / dt); n > 0; --n) push(0.0);
    const double distance = target(random) - p, sign = distance < 0.0 ? -1.0 : 1.0;
    const double ramp = speed / acceleration;
    const bool cruises = std::abs(distance) >= speed * ramp;
    const long ramp_samples = std::lround((cruises ? ramp : std::sqrt(std::abs(distance) / acceleration)) / dt);
    const long cruise_samples = cruises ? std::lround((std::abs(distance) - speed * ramp) / speed / dt) : 0;
    for (long n = 0; n < ramp_samples; ++n) push(sign * acceleration);
    for (long n = 0; n < cruise_samples; ++n) push(0.0);
    for (long n = 0; n < ramp_samples; ++n) push(-sign * acceleration);
    v = 0.0;  // what rounding left of the rate after as many samples down as up
  }
  position.resize(static_cast<std::size_t>(samples + 1));
  rate.resize(static_cast<std::size_t>(samples + 1));
  return {position, rate};
}

/// `seconds` of the rig's PD loop at 1 kHz, tracking a sum of three sines (5, 3 and 2 cm at 0.5, 1.3 and
/// 2.9 Hz; `record` shifts their phases, so record 1 is a second trajectory of the same machine) or
/// point-to-point moves (point_to_point, seeded by `seed`), with the rig's force noise on the motor,
/// simulated by RK4 at 0.25 ms; the log is a CSV with the columns t, encoder_mm (to the count of 1 um)
/// and command (N / gear), in `dir`.
inline std::filesystem::path drive_log(const std::filesystem::path& world_file, const std::filesystem::path& dir,
                                       const DriveRig& rig, double seconds, std::uint64_t seed, int record = 0,
                                       DriveStart start = DriveStart::Tracking,
                                       DriveMotion motion = DriveMotion::Sines) {
  const DynamicsPtr world = find_system(world_file.string())->build(Preset::Simulator, {}, {});
  const double dt = 1e-3, count = 1e-6;
  const auto step = make_step_model(world, Integrator::RK4, dt, 4);
  const auto workspace = step->make_workspace();  // one MuJoCo state for the whole record
  std::mt19937_64 random(seed);
  std::normal_distribution<double> force_noise(0.0, rig.force_noise);
  // The reference and its rate; the log starts with the machine already tracking it (the carriage at
  // the reference), as a record of a running machine does, not with a step of the loop's error.
  const double phase[3] = {0.7 * record, 1.0 + 1.9 * record, 2.0 + 2.3 * record};
  const double amplitude[3] = {0.05, 0.03, 0.02}, frequency[3] = {0.5, 1.3, 2.9};
  const long samples = std::lround(seconds / dt);
  const auto moves = motion == DriveMotion::PointToPoint ? point_to_point(samples, dt, seed)
                                                          : std::pair<std::vector<double>, std::vector<double>>();
  const auto reference_at = [&](double t, bool rate) {
    if (motion == DriveMotion::PointToPoint) {
      const auto k = static_cast<std::size_t>(std::lround(t / dt));
      return rate ? moves.second[k] : moves.first[k];
    }
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double w = 2 * M_PI * frequency[i];
      sum += rate ? amplitude[i] * w * std::cos(w * t + phase[i]) : amplitude[i] * std::sin(w * t + phase[i]);
    }
    return sum;
  };
  Vector x(2), next(2);
  x << reference_at(0.0, false), reference_at(0.0, true);
  if (start == DriveStart::AtRest) x.setZero();
  double previous = std::round((x(0) - x(1) * dt) / count) * count;  // the encoder one sample earlier
  const auto file = dir / fmt::format("drive_log_{}.csv", record);
  std::ofstream out(file);
  out << "t,encoder_mm,command\n";
  for (long k = 0; k <= samples; ++k) {
    const double t = static_cast<double>(k) * dt;
    const double reference = reference_at(t, false);
    const double encoder = std::round(x(0) / count) * count;
    const double speed = (encoder - previous) / dt;
    previous = encoder;
    const double command = (rig.kp() * (reference - encoder) - rig.kd() * speed) / rig.gear;
    out << fmt::format("{:.3f},{:.3f},{:.6f}\n", t, encoder * 1e3, command);
    step->step(x, Vector::Constant(1, command + force_noise(random) / rig.gear), next, nullptr, *workspace);
    x = next;
  }
  if (!out) throw std::runtime_error("cannot write " + file.string());
  return file;
}

/// The import map of the log: positions in mm, velocities by a Savitzky-Golay differentiator of 21
/// samples and degree 2, the command as the control; in `dir`.
inline std::filesystem::path drive_map(const std::filesystem::path& dir) {
  const auto file = dir / "drive_map.toml";
  std::ofstream(file) << "[time]\ncolumn = \"t\"\n\n[states]\nslide = { column = \"encoder_mm\", unit = \"mm\" }\n\n"
                         "[controls]\ndrive = \"command\"\n\n[velocities]\nmethod = \"savitzky_golay\"\nwindow = 21\norder = 2\n";
  return file;
}

}  // namespace gpilqg::test
