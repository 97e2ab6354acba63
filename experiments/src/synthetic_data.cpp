#include "gpilqg/experiments/synthetic_data.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/effects.hpp"
#include "gpilqg/core/input_delay.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/mujoco_system.hpp"

namespace gpilqg {

namespace {

void check_size(const Vector& v, int expected, const char* field) {
  if (v.size() != 0 && v.size() != expected)
    throw std::invalid_argument(std::string("excitation field '") + field + "' has " +
                                std::to_string(v.size()) + " entries; expected " +
                                std::to_string(expected) + " (or none)");
  if (!v.allFinite())
    throw std::invalid_argument(std::string("excitation field '") + field + "' has non-finite entries");
}

/// The system an EffectDynamics decorates, or the system itself.
const Dynamics* bare_system(const Dynamics& system) {
  if (const auto* decorated = dynamic_cast<const EffectDynamics*>(&system)) return &decorated->base();
  return &system;
}

Vector or_default(const Vector& v, int size, double fill) {
  return v.size() == 0 ? Vector::Constant(size, fill) : v;
}

}  // namespace

void ExcitationSettings::validate(int n, int m) const {
  if (episodes < 1) throw std::invalid_argument("excitation 'episodes' = " + std::to_string(episodes) + "; expected >= 1");
  if (steps < 2) throw std::invalid_argument("excitation 'steps' = " + std::to_string(steps) + "; expected >= 2");
  if (!std::isfinite(dt) || dt <= 0.0) throw std::invalid_argument("excitation 'dt' = " + std::to_string(dt) + "; expected > 0");
  if (substeps < 1) throw std::invalid_argument("excitation 'substeps' = " + std::to_string(substeps) + "; expected >= 1");
  if (hold_steps < 1) throw std::invalid_argument("excitation 'hold_steps' = " + std::to_string(hold_steps) + "; expected >= 1");
  check_size(nominal_state, n, "nominal_state");
  check_size(initial_spread, n, "initial_spread");
  check_size(nominal_control, m, "nominal_control");
  check_size(control_amplitude, m, "control_amplitude");
  check_size(observation_std, n, "observation_std");
  if ((observation_std.array() < 0.0).any())
    throw std::invalid_argument("excitation 'observation_std' has negative entries");
  if (!(input_delay >= 0.0 && input_delay <= kMaxInputDelay))
    throw std::invalid_argument("excitation 'input_delay' = " + std::to_string(input_delay) + "; expected a value in [0, " +
                                std::to_string(kMaxInputDelay) + "]");
}

ExcitationSettings default_excitation(const Dynamics& system) {
  ExcitationSettings s;
  const int n = system.state_dim(), m = system.control_dim();
  if (system.name() == "quadrotor") {
    double mass = 0.5, gravity = 9.81;
    for (const auto& p : system.parameters()) {
      if (p.name == "mass") mass = p.value;
      if (p.name == "gravity") gravity = p.value;
    }
    const double hover = mass * gravity / 4.0;
    s.nominal_state = Vector::Zero(n);
    s.nominal_state(2) = 5.0;
    s.initial_spread = Vector::Constant(n, 0.05);
    s.nominal_control = Vector::Constant(m, hover);
    s.control_amplitude = Vector::Constant(m, 0.1 * hover);
    s.steps = 100;
    s.observation_std = Vector::Constant(n, 1e-3);
  } else if (const auto* mujoco = dynamic_cast<const MujocoSystem*>(bare_system(system))) {
    // A MuJoCo model: from rest at the model's zero configuration, the excitation spans the
    // actuators' control ranges (+-1 where unlimited), sampled at the whole timestep nearest 0.02 s.
    const auto [lower, upper] = mujoco->control_limits();
    s.nominal_state = Vector::Zero(n);
    s.initial_spread = Vector::Constant(n, 0.1);
    s.nominal_control = Vector::Zero(m);
    s.control_amplitude = Vector::Ones(m);
    for (int j = 0; j < m; ++j)
      if (std::isfinite(lower(j)) && std::isfinite(upper(j))) {
        s.nominal_control(j) = 0.5 * (lower(j) + upper(j));
        s.control_amplitude(j) = 0.5 * (upper(j) - lower(j));
      }
    s.dt = mujoco->timestep() * std::max(1.0, std::round(0.02 / mujoco->timestep()));
    s.observation_std = Vector::Constant(n, 1e-3);
  } else {
    s.nominal_state = Vector::Zero(n);
    s.initial_spread = Vector::Constant(n, 0.1);
    s.nominal_control = Vector::Zero(m);
    s.control_amplitude = Vector::Constant(m, 5.0);
    s.observation_std = Vector::Constant(n, 1e-3);
  }
  if (m == 0) {
    // A passive system (no controls): free swings from spread initial states, the only excitation.
    // Angles +-1 rad and rates +-0.5 rad/s; lengths +-0.1 m and speeds +-0.05 m/s; other units +-0.5.
    const auto& states = system.states();
    for (int i = 0; i < n; ++i) {
      const std::string& unit = states[static_cast<std::size_t>(i)].unit;
      s.initial_spread(i) = unit == "rad" ? 1.0 : unit == "m" ? 0.1 : unit == "m/s" ? 0.05 : 0.5;
    }
  }
  return s;
}

SyntheticData simulate_measurements(const DynamicsPtr& system, const ExcitationSettings& settings) {
  if (!system) throw std::invalid_argument("simulate_measurements: no system");
  const int n = system->state_dim(), m = system->control_dim();
  settings.validate(n, m);
  const Vector x_nominal = or_default(settings.nominal_state, n, 0.0);
  const Vector spread = or_default(settings.initial_spread, n, 0.0);
  const Vector u_nominal = or_default(settings.nominal_control, m, 0.0);
  const Vector amplitude = or_default(settings.control_amplitude, m, 1.0);
  const Vector obs_std = or_default(settings.observation_std, n, 0.0);

  const auto world_model = make_step_model(system, Integrator::RK4, settings.dt, settings.substeps);
  const StepModel& world = *world_model;
  std::mt19937_64 rng(settings.seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);

  SyntheticData out;
  out.set.system = system->signature();
  const int T = settings.steps;
  for (int e = 0; e < settings.episodes; ++e) {
    Vector x0(n);
    for (int i = 0; i < n; ++i) x0(i) = x_nominal(i) + spread(i) * uniform(rng);
    // T controls: the last one is recorded with the last sample and has no successor state.
    Matrix u(m, T);
    for (int t = 0; t < T; ++t) {
      if (t % settings.hold_steps == 0)
        for (int j = 0; j < m; ++j) u(j, t) = u_nominal(j) + amplitude(j) * uniform(rng);
      else
        u.col(t) = u.col(t - 1);
    }
    const Matrix applied = delay_controls(u.transpose(), settings.input_delay).transpose();
    const RolloutResult r = rollout(world, x0, applied.leftCols(T - 1), RolloutNoise::Process, &rng);
    const int samples = r.steps_completed + 1;
    if (!r.finite) ++out.truncated_episodes;
    if (samples < 2) continue;

    Episode episode;
    episode.id = e;
    episode.t.resize(samples);
    for (int k = 0; k < samples; ++k) episode.t(k) = k * settings.dt;  // exact multiples of dt
    episode.x = r.trajectory.x.leftCols(samples).transpose();
    episode.u = u.leftCols(samples).transpose();
    for (int k = 0; k < samples; ++k)
      for (int i = 0; i < n; ++i) episode.x(k, i) += obs_std(i) * normal(rng);
    out.set.episodes.push_back(std::move(episode));
  }
  if (out.set.episodes.empty())
    throw ExcitationDiverged("every simulated episode diverged before its second sample");
  return out;
}

}  // namespace gpilqg
