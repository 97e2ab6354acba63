#pragma once
/// @file ball_drive.hpp
/// A position-controlled drive logged as real drives are: tests/experiments/models/ball_drive.xml (a
/// carriage of 2 kg on a slide, driven by a force) in a PD loop at 1 kHz on an encoder of 1 um, the log
/// holding the encoder's position and the commanded force only, one continuous record. The "real"
/// drive is the same file with viscous friction (MuJoCo's joint damping), Coulomb friction (its
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

#include <fmt/format.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/system_registry.hpp"

namespace gpilqg::test {

struct DriveTruth {
  double damping = 30.0;   ///< N s/m
  double friction = 5.0;   ///< N
  double constant = 3.0;   ///< N: the carriage's 2 kg times a gravity of 1.5 m/s^2 along the slide
};

inline std::filesystem::path drive_model(const std::filesystem::path& source_dir) {
  return source_dir / "tests" / "experiments" / "models" / "ball_drive.xml";
}

/// The world: `model` with the three effects of `truth` written into the file, in `dir`.
inline std::filesystem::path drive_world(const std::filesystem::path& model, const std::filesystem::path& dir,
                                         const DriveTruth& truth) {
  std::ifstream in(model);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    if (at == std::string::npos) throw std::runtime_error(model.string() + ": no '" + from + "'");
    text.replace(at, from.size(), to);
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

/// `seconds` of the PD loop (3000 N/m, 60 N s/m on the encoder's difference quotient) at 1 kHz,
/// tracking a sum of three sines (5, 3 and 2 cm at 0.5, 1.3 and 2.9 Hz), with force noise of 0.3 N on
/// the motor, simulated by RK4 at 0.25 ms; the log is a CSV with the columns t, encoder_mm (to the
/// count of 1 um) and force_N, in `dir`.
inline std::filesystem::path drive_log(const std::filesystem::path& world_file, const std::filesystem::path& dir,
                                       double seconds, std::uint64_t seed) {
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
  if (!out) throw std::runtime_error("cannot write " + file.string());
  return file;
}

/// The import map of the log: positions in mm, velocities by a Savitzky-Golay differentiator of 21
/// samples and degree 2, the force as the control; in `dir`.
inline std::filesystem::path drive_map(const std::filesystem::path& dir) {
  const auto file = dir / "drive_map.toml";
  std::ofstream(file) << "[time]\ncolumn = \"t\"\n\n[states]\nslide = { column = \"encoder_mm\", unit = \"mm\" }\n\n"
                         "[controls]\ndrive = \"force_N\"\n\n[velocities]\nmethod = \"savitzky_golay\"\nwindow = 21\norder = 2\n";
  return file;
}

}  // namespace gpilqg::test
