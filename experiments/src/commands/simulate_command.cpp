/// `gpilqg simulate`: synthetic measurements from a system preset under random excitation, with
/// process noise and observation noise, written in the measurement contract (CSV or HDF5).

#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/synthetic_data.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "world_options.hpp"

namespace gpilqg::cli {

namespace {

struct SimulateOptions {
  WorldOptions world;
  std::string out;
  int episodes = -1;
  int steps = -1;
  double dt = -1.0;
  double observation_noise = -1.0;
  std::uint64_t seed = 1;
};

int run_simulate(const SimulateOptions& o) {
  check_output_file_option("--out", o.out, {"simulate writes a measurement file (CSV or HDF5)", kMeasurementExtensions},
                           world_inputs(o.world));
  const auto signature = system_signature(o.world.system);
  const int n = static_cast<int>(signature.states.size());
  double input_delay = 0.0;
  const auto system = build_world(o.world, &input_delay);

  ExcitationSettings settings = default_excitation(*system);
  settings.input_delay = input_delay;
  if (o.episodes > 0) settings.episodes = o.episodes;
  if (o.steps > 0) settings.steps = o.steps;
  if (o.dt > 0.0) settings.dt = o.dt;
  if (o.observation_noise >= 0.0) settings.observation_std = Vector::Constant(n, o.observation_noise);
  settings.seed = o.seed;
  if (static_cast<double>(settings.episodes) * settings.steps > static_cast<double>(limits::kMaxSamples))
    throw InputError(fmt::format("--episodes {} x --steps {}: {} samples; expected at most {} (the sample limit)",
                                 settings.episodes, settings.steps, static_cast<double>(settings.episodes) * settings.steps,
                                 limits::kMaxSamples));

  SyntheticData data;
  try {
    data = simulate_measurements(system, settings);
  } catch (const ExcitationDiverged& e) {
    // The excitation's amplitude is the system's default; the step is this command's to choose.
    throw InputError(fmt::format("{} at --dt {} s; expected a shorter --dt", e.what(), settings.dt));
  }
  data.set.system = signature;
  write_measurements(o.out, data.set);
  std::cout << fmt::format("wrote {}: {} {}, {} episodes, {} samples, dt = {} s, seed {}\n", o.out,
                           o.world.system, world_setting(o.world), data.set.episodes.size(), data.set.sample_count(),
                           settings.dt, o.seed);
  if (data.truncated_episodes > 0)
    std::cout << fmt::format("note: {} episode(s) diverged and were cut at their last finite sample\n",
                             data.truncated_episodes);
  return kExitSuccess;
}

}  // namespace

void add_simulate_command(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<SimulateOptions>();
  auto* cmd = app.add_subcommand(
      "simulate", "Write synthetic measurements: a system preset under random excitation, with noise");
  add_world_options(*cmd, options->world);
  cmd->add_option("--episodes", options->episodes, "Number of episodes (default per system)")
      ->check(integer_in(1, limits::kMaxRollouts));
  cmd->add_option("--steps", options->steps, "Samples per episode (default per system)")
      ->check(integer_in(2, limits::kMaxSamples));
  cmd->add_option("--dt", options->dt, "Sampling step in seconds (default 0.02)")->check(positive_number());
  cmd->add_option("--observation-noise", options->observation_noise,
                  "Std of Gaussian noise on each recorded state (default 1e-3; at most the divergence bound 1e12)")
      ->check(number_in(0.0, kDivergedStateMagnitude));
  cmd->add_option("--seed", options->seed, "Random seed; the same seed gives the same file")
      ->capture_default_str()
      ->check(integer_in(0, static_cast<long long>(limits::kMaxSeed)));
  cmd->add_option("--out", options->out, "Output file (.csv, .h5 or .hdf5)")->required();
  cmd->callback([&action, options] { action = [options] { return run_simulate(*options); }; });
}

}  // namespace gpilqg::cli
