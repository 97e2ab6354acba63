#include "gpilqg/experiments/diagnosis/criterion_choice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <Eigen/LU>
#include <fmt/format.h>

#include "gpilqg/core/effects.hpp"
#include "gpilqg/core/generalised_forces.hpp"
#include "gpilqg/core/savitzky_golay.hpp"
#include "gpilqg/experiments/diagnosis/accelerations.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/derivative_window.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/heldout_blocks.hpp"
#include "gpilqg/experiments/diagnosis/motion_period.hpp"

namespace gpilqg::diagnosis {

namespace {

/// Relative tolerance on the gains of the controls (G) and on their reach outside the velocities.
constexpr double kGainTolerance = 1e-4;
/// States at which the gains are compared.
constexpr int kGainSamples = 8;
/// Rows at which the control's error in the acceleration estimate is averaged (evenly strided).
constexpr long kControlErrorRows = 2000;

/// The generalised-force map of the system `model` uses (force_map_owner), or null.
const GeneralisedForceInput* force_input(const Dynamics& model) {
  return dynamic_cast<const GeneralisedForceInput*>(force_map_owner(model));
}

/// The coordinates of the model's force components, when every component has one (else empty).
std::vector<GeneralisedCoordinate> force_coordinates(const Dynamics& model) {
  const GeneralisedForceInput* input = force_input(model);
  if (input == nullptr) return {};
  std::vector<GeneralisedCoordinate> coordinates(input->generalised_forces().size());
  std::vector<bool> found(coordinates.size(), false);
  for (const GeneralisedCoordinate& c : generalised_coordinates(*force_map_owner(model))) {
    coordinates[static_cast<std::size_t>(c.component)] = c;
    found[static_cast<std::size_t>(c.component)] = true;
  }
  if (std::find(found.begin(), found.end(), false) != found.end()) return {};
  return coordinates;
}

/// The velocity states (file comment of the header): the coordinates', else `<q>_dot`, else all.
std::vector<int> velocity_states(const std::vector<GeneralisedCoordinate>& coordinates, const SystemSignature& system) {
  std::vector<int> out;
  for (const GeneralisedCoordinate& c : coordinates) out.push_back(c.velocity);
  if (!out.empty()) return out;
  for (int i = 0; i < static_cast<int>(system.states.size()); ++i)
    if (position_by_name(system, i) >= 0) out.push_back(i);
  if (!out.empty()) return out;
  for (int i = 0; i < static_cast<int>(system.states.size()); ++i) out.push_back(i);
  return out;
}

/// The sample `index` of all samples of `data` counted episode after episode: (episode, row).
std::pair<const Episode*, Eigen::Index> sample_at(const MeasurementSet& data, long index) {
  for (const Episode& e : data.episodes) {
    if (index < e.length()) return {&e, index};
    index -= e.length();
  }
  return {&data.episodes.back(), data.episodes.back().length() - 1};
}

/// G (k x m) at (x, u), the generalised force per unit of each control, from the system's own
/// actuation (GeneralisedForceInput::control_forces, applied as `model` applies its controls: k u
/// under an EffectDynamics' gain k): G_j = Q_u(x, k (u + e_j)) - Q_u(x, k u), exact for actuators
/// linear in their input. False when the system does not compute its actuation or an effect's force
/// depends on the controls; the caller then takes W_v^-1 df_v/du from the forward Jacobian.
bool actuation_gain(const Dynamics& model, const VectorCRef& x, const VectorCRef& u, Matrix& G) {
  double gain = 1.0;
  if (const auto* decorated = dynamic_cast<const EffectDynamics*>(&model)) {
    if (decorated->input_dependent()) return false;
    gain = decorated->actuator_gain();
  }
  const Dynamics* owner = force_map_owner(model);
  const GeneralisedForceInput* input = force_input(model);
  if (input == nullptr) return false;
  const auto k = static_cast<Eigen::Index>(input->generalised_forces().size());
  const auto workspace = owner->make_workspace();
  Vector base(k), moved(k);
  const Vector applied = gain * u;
  if (!input->control_forces(x, applied, base, *workspace)) return false;
  G.resize(k, u.size());
  for (Eigen::Index j = 0; j < u.size(); ++j) {
    Vector step = applied;
    step(j) += gain;
    input->control_forces(x, step, moved, *workspace);
    G.col(j) = moved - base;
  }
  return G.allFinite();
}

/// Why the controls of `model` are not generalised forces with a constant gain (header, rule 2), or
/// "" when they are.
std::string why_not_forces(const Dynamics& model, const std::vector<GeneralisedCoordinate>& coordinates,
                           const MeasurementSet& data) {
  const GeneralisedForceInput* input = force_input(model);
  if (input == nullptr) return fmt::format("system '{}' has no generalised-force map", model.name());
  if (coordinates.empty())
    return fmt::format("a generalised force of system '{}' acts on no coordinate with a velocity state", model.name());
  const auto k = static_cast<Eigen::Index>(coordinates.size());
  const int n = model.state_dim(), m = model.control_dim();
  std::vector<bool> velocity_row(static_cast<std::size_t>(n), false);
  for (const GeneralisedCoordinate& c : coordinates) velocity_row[static_cast<std::size_t>(c.velocity)] = true;

  const long total = data.sample_count();
  DynamicsJacobians jac;
  Vector xdot(n);
  Matrix W;
  Matrix reference;  // G at the first state
  for (int s = 0; s < 2 * kGainSamples; ++s) {
    // Samples spread over the data; the second half pairs each state with another sample's control.
    const long i = (static_cast<long>(s % kGainSamples) * total) / kGainSamples;
    const auto [episode, row] = sample_at(data, i);
    const Vector x = episode->x.row(row).transpose();
    const auto [other, other_row] = sample_at(data, (i + total / 2) % total);
    const Vector u = (s < kGainSamples ? episode->u.row(row) : other->u.row(other_row)).transpose();
    model.evaluate(x, u, xdot, &jac);
    for (int j = 0; j < m; ++j) {
      const double scale = jac.fu.col(j).cwiseAbs().maxCoeff();
      for (int r = 0; r < n; ++r)
        if (!velocity_row[static_cast<std::size_t>(r)] && std::abs(jac.fu(r, j)) > kGainTolerance * scale)
          return fmt::format("control '{}' drives state '{}', not the velocity of a coordinate",
                             data.system.controls[static_cast<std::size_t>(j)].name,
                             data.system.states[static_cast<std::size_t>(r)].name);
    }
    input->generalised_force_map(x, W, nullptr);
    Matrix Wv(k, k), bv(k, m);
    for (Eigen::Index c = 0; c < k; ++c) {
      Wv.row(c) = W.row(coordinates[static_cast<std::size_t>(c)].velocity);
      bv.row(c) = jac.fu.row(coordinates[static_cast<std::size_t>(c)].velocity);
    }
    const Eigen::FullPivLU<Matrix> lu(Wv);
    if (!lu.isInvertible()) return "the generalised-force map is singular at a measured state";
    Matrix G;
    if (!actuation_gain(model, x, u, G)) G = lu.solve(bv);
    if (s == 0) {
      reference = G;
      if (reference.cwiseAbs().maxCoeff() == 0.0) return "the controls do not act on the model";
      continue;
    }
    const double scale = reference.cwiseAbs().maxCoeff();
    Eigen::Index r = 0, c = 0;
    const double change = (G - reference).cwiseAbs().maxCoeff(&r, &c);
    if (change > kGainTolerance * scale)
      return fmt::format("the generalised force of control '{}' on coordinate '{}' changes with the {} by {:.2g}% of "
                         "the largest gain",
                         data.system.controls[static_cast<std::size_t>(c)].name,
                         coordinates[static_cast<std::size_t>(r)].name, s < kGainSamples ? "state" : "control",
                         100.0 * change / scale);
  }
  return "";
}

/// rho of one velocity state (header, rule 2), with its window and the controls' share of E_ID.
struct StateRatio {
  double ratio = 0.0;
  int window = 0;
  double control_error = 0.0;  ///< sqrt(mean a_h^2) / E_ID
  double smear_error = 0.0;    ///< sqrt(mean a_s^2) / E_ID
  /// sqrt((mean a_s^2 + mean a_h^2) / mean |b_v u|^2): the filter's misfit on the model against the
  /// force the controls apply (infinite when they apply none)
  double misfit = 0.0;
  /// kappa (header): how much of the velocity's motion about its mean the window's mean keeps, its
  /// noise discounted (1 when it does not move)
  double kept = 1.0;
};

/// The white-noise level of a sampled signal robust to isolated corners and steps: for each order
/// k = k_min..k_max the median of |Delta^k y| pooled over the segments, over its value for white noise
/// of unit variance (0.6745 sqrt(C(2k, k)), Delta^k e being normal with variance C(2k, k)), the
/// smallest over k. A median ignores the differences a held control's steps (in the control) or
/// corners (in the velocity) spoil as long as they are fewer than half, where the mean of squares of
/// difference_noise_std takes them for noise; that matters for E_1, which is the noise alone. The
/// smallest k that a smooth trend does not dominate wins, as in difference_noise_std.
double robust_noise_std(const std::vector<Vector>& segments, int k_min, int k_max) {
  double best = std::numeric_limits<double>::infinity();
  for (int k = k_min; k <= k_max; ++k) {
    std::vector<double> magnitudes;
    for (const Vector& y : segments) {
      if (y.size() <= k) continue;
      Vector d = y;
      for (int order = 0; order < k; ++order) d = (d.tail(d.size() - 1) - d.head(d.size() - 1)).eval();
      for (Eigen::Index i = 0; i < d.size(); ++i) magnitudes.push_back(std::abs(d(i)));
    }
    if (magnitudes.empty()) continue;
    const auto mid = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
    std::nth_element(magnitudes.begin(), mid, magnitudes.end());
    double binomial = 1.0;  // C(2k, k)
    for (int i = 1; i <= k; ++i) binomial = binomial * (k + i) / i;
    best = std::min(best, *mid / (0.674489750196 * std::sqrt(binomial)));
  }
  return std::isfinite(best) ? best : 0.0;
}

/// The segments of state column `state` long enough to be differentiated.
std::vector<Vector> state_segments(const MeasurementSet& data, int state) {
  std::vector<Vector> segments;
  for (const Episode& e : data.episodes)
    if (e.length() >= shortest_differentiable_segment(2)) segments.push_back(e.x.col(state));
  return segments;
}

/// The model's state derivative f(x_t, u_t) at every sample of every episode, as measured (T x n each).
std::vector<Matrix> model_derivatives(const Dynamics& model, const MeasurementSet& data) {
  const auto workspace = model.make_workspace();
  Vector xdot(model.state_dim());
  std::vector<Matrix> out;
  for (const Episode& e : data.episodes) {
    Matrix f(e.length(), model.state_dim());
    for (Eigen::Index r = 0; r < e.length(); ++r) {
      model.evaluate(e.x.row(r).transpose(), e.u.row(r).transpose(), xdot, nullptr, *workspace);
      f.row(r) = xdot.transpose();
    }
    out.push_back(std::move(f));
  }
  return out;
}

/// Every sample of episode `index` of `data` as a row of Transitions (x_next is not set): what
/// generalised_force_parts evaluates at each sample, the last of the episode included.
Transitions episode_samples(const MeasurementSet& data, std::size_t index) {
  const Episode& e = data.episodes[index];
  Transitions out;
  out.x = e.x;
  out.u = e.u;
  out.t = e.t;
  out.episode.assign(static_cast<std::size_t>(e.length()), static_cast<int>(index));
  out.heldout.assign(static_cast<std::size_t>(e.length()), false);
  return out;
}

/// The model's generalised force at every sample, F_t = W_v(x_t)^-1 f_v(x_t, u_t) (T x k each, column
/// i for force component i): what the inverse-dynamics criterion filters (criteria/inverse_dynamics.hpp),
/// minus the residual's force term at zero acceleration (generalised_force_parts).
std::vector<Matrix> model_forces(const Dynamics& model, const MeasurementSet& data, Eigen::Index k) {
  std::vector<Matrix> out;
  for (std::size_t episode = 0; episode < data.episodes.size(); ++episode) {
    const Transitions samples = episode_samples(data, episode);
    std::vector<int> rows(static_cast<std::size_t>(samples.size()));
    std::iota(rows.begin(), rows.end(), 0);
    out.push_back(-generalised_force_parts(model, samples, samples.u, Matrix::Zero(samples.size(), k), rows).forces);
  }
  return out;
}

/// A sample at which the rule averages (every stride-th of the episodes a window fits, at most
/// kControlErrorRows): its window [start, start + window) of the acceleration estimate, and the model
/// there, evaluated once for every velocity state.
struct SampledRow {
  std::size_t episode = 0;
  Eigen::Index t = 0, start = 0;
  Matrix fu;  ///< n x m, df/du at (x_t, u_t)
  Matrix W;   ///< n x k, the generalised-force map at x_t
};

std::vector<SampledRow> sampled_rows(const Dynamics& model, const MeasurementSet& data, int window) {
  long rows = 0;
  for (const Episode& e : data.episodes)
    if (e.length() >= window) rows += e.length();
  const long stride = std::max(1L, rows / kControlErrorRows);
  DynamicsJacobians jac;
  Vector xdot(model.state_dim());
  const auto workspace = model.make_workspace();
  const GeneralisedForceInput* input = force_input(model);
  const auto map_workspace = force_map_owner(model)->make_workspace();
  std::vector<SampledRow> out;
  long position = 0;
  for (std::size_t episode = 0; episode < data.episodes.size(); ++episode) {
    const Episode& e = data.episodes[episode];
    if (e.length() < window) continue;
    // Every sample at its place in its window: centred, or off-centre at the episode's ends, where
    // the estimate is noisier and no longer zero-phase (on short episodes most samples are there).
    for (Eigen::Index t = 0; t < e.length(); ++t, ++position) {
      if (position % stride != 0) continue;
      SampledRow row;
      row.episode = episode;
      row.t = t;
      row.start = std::clamp<Eigen::Index>(t - window / 2, 0, e.length() - window);
      model.evaluate(e.x.row(t).transpose(), e.u.row(t).transpose(), xdot, &jac, *workspace);
      row.fu = jac.fu;
      input->generalised_force_map(e.x.row(t).transpose(), row.W, nullptr, *map_workspace);
      out.push_back(std::move(row));
    }
  }
  return out;
}

/// The noise of each control, which both residuals carry (b_v n_u in acceleration units), the
/// inverse-dynamics one seen through the filter (|m|^2 of its variance).
Vector controls_noise(const MeasurementSet& data, int controls) {
  Vector out(controls);
  for (int j = 0; j < controls; ++j) {
    std::vector<Vector> columns;
    for (const Episode& e : data.episodes) columns.push_back(e.u.col(j));
    out(j) = robust_noise_std(columns, 1, 2);
  }
  return out;
}

/// rho of velocity state `state` with the acceleration estimate `estimate` (the one filter of every
/// coordinate, accelerations.hpp) of the column `differentiated` (the state itself or its measured
/// position); `own` the model's derivatives at the samples (model_derivatives), `forces` its
/// generalised forces there (model_forces), `sampled` the rows it averages over (sampled_rows) and
/// `control_noise` the noise of each control (controls_noise).
StateRatio state_ratio(const MeasurementSet& data, const std::vector<Matrix>& own, const std::vector<Matrix>& forces,
                       const std::vector<SampledRow>& sampled, const Vector& control_noise, int state,
                       int differentiated, double dt, const AccelerationFilter& estimate) {
  const std::vector<Vector> segments = state_segments(data, state);
  const int window = estimate.window;
  StateRatio out;
  if (segments.empty()) return out;
  out.window = window;
  const SavitzkyGolayDerivative filter(window, estimate.order, estimate.derivative);
  // The weights on the accelerations at every place in the window (accelerations.hpp), for a
  // continuous control and for one held over each step.
  std::vector<Vector> continuous, held;
  for (int p = 0; p < window; ++p) {
    continuous.push_back(acceleration_weights(filter, p, ControlHold::Continuous));
    held.push_back(acceleration_weights(filter, p, ControlHold::ZeroOrder));
  }

  double hold = 0.0, smear = 0.0, shared = 0.0, gain = 0.0, filtered_noise = 0.0, applied = 0.0, kept = 0.0, motion = 0.0;
  long count = 0;
  std::vector<double> mean_velocity;
  for (const Episode& e : data.episodes) mean_velocity.push_back(e.x.col(state).mean());
  double kept_noise = 0.0;
  for (const SampledRow& row : sampled) {
    const Episode& e = data.episodes[row.episode];
    const Eigen::Index t = row.t, start = row.start;
    const auto p = static_cast<std::size_t>(t - start);
    const auto u = e.u.middleRows(start, window).transpose();
    // The two holds' filtered controls differ by what the data cannot tell apart.
    const Vector du = u * (continuous[p] - held[p]);
    // What the filter smears: the window's mean of the model's acceleration against the window's
    // mean of its generalised force seen through the inertia at x_t (0 when the inertia does not
    // change over the window, however sharply the forces do).
    const Vector mean_force = forces[row.episode].middleRows(start, window).transpose() * continuous[p];
    smear += std::pow(own[row.episode].col(state).segment(start, window).dot(continuous[p]) -
                          row.W.row(state).dot(mean_force),
                      2);
    hold += std::pow(row.fu.row(state).dot(du), 2);
    applied += std::pow(row.fu.row(state).dot(e.u.row(t)), 2);
    // How much of the velocity's motion about its mean the window's mean keeps, with the noise.
    const double centre = mean_velocity[row.episode];
    kept += std::pow(e.x.col(state).segment(start, window).dot(continuous[p]) - centre, 2);
    motion += std::pow(e.x(t, state) - centre, 2);
    kept_noise += continuous[p].squaredNorm();
    const double noise = row.fu.row(state).cwiseProduct(control_noise.transpose()).squaredNorm();
    shared += noise;
    filtered_noise += noise * continuous[p].squaredNorm();
    gain += filter.weights(static_cast<int>(p)).squaredNorm();
    ++count;
  }
  const double n = std::max(1.0, static_cast<double>(count));
  const double hold_mse = hold / n, smear_mse = smear / n, shared_mse = shared / n;
  const double sigma = robust_noise_std(segments, 2, 4);
  // The estimate's own noise: that of the column it differentiates, through its weights.
  const double sigma_differentiated =
      differentiated == state ? sigma : robust_noise_std(state_segments(data, differentiated), 2, 4);
  const double step = estimate.derivative == 2 ? dt * dt : dt;
  const double e1_squared = 2.0 * sigma * sigma / (dt * dt) + shared_mse;
  const double eid_squared = sigma_differentiated * sigma_differentiated * gain / n / (step * step) + smear_mse +
                             hold_mse + filtered_noise / n;
  out.ratio = eid_squared > 0.0 ? std::sqrt(e1_squared / eid_squared)
                                : (e1_squared > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  out.control_error = eid_squared > 0.0 ? std::sqrt(hold_mse / eid_squared) : 0.0;
  out.smear_error = eid_squared > 0.0 ? std::sqrt(smear_mse / eid_squared) : 0.0;
  // The measured velocity's white noise, sigma^2 per sample, |m|^2 sigma^2 through the window's mean.
  const double kept_signal = kept - sigma * sigma * kept_noise, motion_signal = motion - sigma * sigma * n;
  out.kept = motion_signal > 0.0 ? std::sqrt(std::max(0.0, kept_signal) / motion_signal) : 1.0;
  out.misfit = applied > 0.0 ? std::sqrt((smear + hold) / applied) : std::numeric_limits<double>::infinity();
  return out;
}

/// sigma_v^2 / var(v) of one velocity state (rule 2, the IV form): the robust noise level of
/// state_ratio over the variance of every sample of the state.
double attenuation(const MeasurementSet& data, int state) {
  std::vector<Vector> segments;
  double sum = 0.0, squares = 0.0;
  long count = 0;
  for (const Episode& e : data.episodes) {
    segments.push_back(e.x.col(state));
    sum += e.x.col(state).sum();
    squares += e.x.col(state).squaredNorm();
    count += e.length();
  }
  if (count < 2) return 0.0;
  const double mean = sum / static_cast<double>(count);
  const double variance = squares / static_cast<double>(count) - mean * mean;
  const double sigma = robust_noise_std(segments, 2, 4);
  return variance > 0.0 ? sigma * sigma / variance : 0.0;
}

std::string seconds(double value) { return fmt::format("{:.3g} s", value); }

std::string names(const std::vector<std::string>& list) { return fmt::format("{}", fmt::join(list, ", ")); }

/// The period of velocity state `velocity` (header: the window). A velocity the import estimated from
/// its position `<q>` carries the derivative filter's noise, correlated over the filter's window, which
/// the differences of the column do not see: the hysteresis band is then too narrow and noise crossings
/// shorten the period (a 1 kHz encoder's pendulum of period 0.93 s measured 0.14 s). The position
/// oscillates with the same period and carries the sensor's white noise, so its period is used; a
/// position that drifts (no finite period) says nothing of the oscillation, and the velocity's own is
/// kept.
MotionPeriod velocity_period(const MeasurementSet& data, int velocity) {
  const std::vector<int> positions = estimated_velocity_positions(data);
  const int position = positions.empty() ? -1 : positions[static_cast<std::size_t>(velocity)];
  if (position >= 0) {
    const MotionPeriod of_position = motion_period(data, position);
    if (!of_position.still && std::isfinite(of_position.period)) return of_position;
  }
  return motion_period(data, velocity);
}

/// W and the phrase that says how it was chosen (header: the window).
std::pair<int, std::string> simulation_window(const MeasurementSet& data, const std::vector<int>& states,
                                              CriterionFacts& facts) {
  const double dt = facts.dt;
  facts.window_cap = simulation_window_cap(data);
  const std::string cap_text =
      data.episodes.size() == 1
          ? fmt::format("capped at {} samples so that a training block of the record (cut into {} blocks) keeps two "
                        "windows beside the gaps",
                        facts.window_cap, kHeldoutBlockCount)
          : fmt::format("capped at {} samples, half the shortest episode", facts.window_cap);
  bool moving = false;
  for (int s : states) {
    const MotionPeriod p = velocity_period(data, s);
    if (p.still) continue;
    if (!moving || p.period > facts.slowest_period) {
      facts.slowest_period = p.period;
      facts.slowest_state = data.system.states[static_cast<std::size_t>(p.state)].name;
    }
    moving = true;
  }
  if (!moving)
    return {facts.window_cap, "no velocity state moves beyond its noise, so the longest window: " + cap_text};
  if (!std::isfinite(facts.slowest_period))
    return {facts.window_cap, fmt::format("the slowest motion, {}, is slower than the episodes: {}", facts.slowest_state,
                                          cap_text)};
  const double periods = 2.0 * facts.slowest_period / dt;
  const std::string two_periods =
      fmt::format("two periods of the slowest motion, {}'s {}", facts.slowest_state, seconds(facts.slowest_period));
  if (periods > facts.window_cap) return {facts.window_cap, fmt::format("{}: {}", two_periods, cap_text)};
  if (periods < kMinWindow)
    return {std::min(kMinWindow, facts.window_cap),
            fmt::format("the shortest window; {} last {:.3g} samples", two_periods, periods)};
  return {static_cast<int>(std::lround(periods)), two_periods};
}

/// Rules 1 and 3: the simulation criterion, its window, and the reason `why`; one-step when no window fits.
CriterionChoice simulation_choice(const MeasurementSet& data, const std::vector<int>& states, CriterionFacts& facts,
                                  const std::string& why) {
  CriterionChoice choice;
  const auto [window, how] = simulation_window(data, states, facts);
  choice.facts = facts;
  if (window < 2) {
    choice.reason = fmt::format(
        "one-step: the simulation criterion is called for ({}), but no window of 2 samples or more fits the "
        "episodes ({})",
        why, how);
    return choice;
  }
  choice.criterion = FitCriterion::Simulation;
  choice.window = window;
  choice.reason =
      fmt::format("simulation over windows of {} samples ({}, {}): {}", window, seconds(window * facts.dt), how, why);
  return choice;
}

}  // namespace

int simulation_window_cap(const MeasurementSet& data) {
  if (data.episodes.empty()) return 0;
  if (data.episodes.size() == 1) {
    const int block = data.episodes.front().length() / kHeldoutBlockCount;
    return std::max(0, (block - 2) / 4);
  }
  int shortest = std::numeric_limits<int>::max();
  for (const Episode& e : data.episodes) shortest = std::min(shortest, e.length());
  return shortest / 2;
}

CriterionChoice choose_criterion(const MeasurementSet& data, const ModelSpec& model) {
  if (data.episodes.empty()) throw DataProblem("criterion choice: the measurement set has no episodes");
  const DynamicsPtr dynamics = model.build();
  if (dynamics->state_dim() != static_cast<int>(data.system.states.size()) ||
      dynamics->control_dim() != static_cast<int>(data.system.controls.size()))
    throw DataProblem(fmt::format(
        "criterion choice: the model '{}' has {} states and {} controls; the data of '{}' have {} and {}",
        dynamics->name(), dynamics->state_dim(), dynamics->control_dim(), data.system.name,
        data.system.states.size(), data.system.controls.size()));

  CriterionChoice choice;
  CriterionFacts& facts = choice.facts;
  facts.dt = data.episodes.front().dt();
  facts.passive = data.system.controls.empty();
  facts.estimated_states = data.estimated_states;
  const std::vector<GeneralisedCoordinate> coordinates = force_coordinates(*dynamics);
  const std::vector<int> states = velocity_states(coordinates, data.system);
  for (int s : states) facts.velocity_states.push_back(data.system.states[static_cast<std::size_t>(s)].name);

  // 1. Passive: simulation.
  if (facts.passive)
    return simulation_choice(data, states, facts,
                             "the system has no controls, so the data are a free response whose decay accumulates over "
                             "periods but is below the noise of one step when it is light");

  // 2. Generalised forces, and accelerations the filter estimates well: inverse dynamics.
  const bool estimated = !facts.estimated_states.empty();
  const std::string estimated_why =
      estimated ? fmt::format("{} {} estimated from other states (e.g. by the import)", names(facts.estimated_states),
                              facts.estimated_states.size() == 1 ? "was" : "were")
                : std::string();
  // Rule 3: estimated velocities and no inverse dynamics, `because` says why not.
  const auto estimated_simulation = [&](const std::string& because) {
    return simulation_choice(data, states, facts,
                             fmt::format("{}, and a one-step fit regresses on them: biased, as errors in the variables "
                                         "are; {}",
                                         estimated_why, because));
  };
  facts.forces_checked = true;
  facts.not_forces = why_not_forces(*dynamics, coordinates, data);
  if (!facts.not_forces.empty()) {
    if (estimated)
      return estimated_simulation(fmt::format(
          "{}, so the inverse-dynamics residual is not the generalised force the model misses", facts.not_forces));
    choice.reason = fmt::format("one-step: the velocities are measured and the system is driven, but {}, so the "
                                "inverse-dynamics residual is not the generalised force the model misses",
                                facts.not_forces);
    return choice;
  }
  // The one filter of the acceleration estimate: of the velocities, or of the measured positions when
  // every velocity was estimated from its position; the widest of the coordinates' own windows
  // (accelerations.hpp).
  std::vector<int> coordinate_velocities;
  for (const GeneralisedCoordinate& c : coordinates) coordinate_velocities.push_back(c.velocity);
  const DifferentiatedColumns columns = differentiated_columns(estimated_velocity_positions(data), coordinate_velocities);
  AccelerationFilter filter{0, 2, columns.derivative};
  for (const int column : columns.states) {
    const std::vector<Vector> segments = state_segments(data, column);
    if (!segments.empty())
      filter.window =
          std::max(filter.window, choose_derivative_window(segments, facts.dt, filter.order, filter.derivative).window);
  }
  facts.acceleration_derivative = filter.derivative;
  facts.ratio = std::numeric_limits<double>::infinity();
  const std::vector<Matrix> own = filter.window > 0 ? model_derivatives(*dynamics, data) : std::vector<Matrix>();
  const std::vector<Matrix> forces =
      filter.window > 0 ? model_forces(*dynamics, data, static_cast<Eigen::Index>(coordinates.size()))
                        : std::vector<Matrix>();
  const std::vector<SampledRow> sampled =
      filter.window > 0 ? sampled_rows(*dynamics, data, filter.window) : std::vector<SampledRow>();
  const Vector control_noise = controls_noise(data, dynamics->control_dim());
  for (std::size_t i = 0; i < coordinates.size(); ++i) {
    if (filter.window == 0) break;
    const GeneralisedCoordinate& c = coordinates[i];
    const StateRatio r =
        state_ratio(data, own, forces, sampled, control_noise, c.velocity, columns.states[i], facts.dt, filter);
    const std::string name = data.system.states[static_cast<std::size_t>(c.velocity)].name;
    if (r.ratio < facts.ratio || facts.ratio_state.empty()) {
      facts.ratio = r.ratio;
      facts.ratio_state = name;
      facts.acceleration_window = r.window;
      facts.control_error = r.control_error;
      facts.smear_error = r.smear_error;
    }
    if (r.misfit > facts.misfit || facts.misfit_state.empty()) {
      facts.misfit = r.misfit;
      facts.misfit_state = name;
    }
    if (r.kept < facts.motion_kept || facts.motion_kept_state.empty()) {
      facts.motion_kept = r.kept;
      facts.motion_kept_state = name;
    }
  }
  if (facts.acceleration_window == 0) {
    facts.ratio = 0.0;
    facts.misfit = 0.0;
    facts.motion_kept = 0.0;
    const std::string too_short = fmt::format(
        "every episode is shorter than the {} samples an acceleration estimate needs", shortest_differentiable_segment(2));
    if (estimated) return estimated_simulation(too_short);
    choice.reason = "one-step: " + too_short;
    return choice;
  }
  const std::string measured = fmt::format(
      "{}: acceleration window of {} samples at {:.4g} Hz; of its mean squared error {:.0f}% from the inertia's "
      "change over the window, {:.0f}% from not knowing how the controls are held",
      facts.ratio_state, facts.acceleration_window, 1.0 / facts.dt, 100.0 * facts.smear_error * facts.smear_error,
      100.0 * facts.control_error * facts.control_error);
  const std::string misfit = fmt::format(
      "the filter's misfit on the model (the inertia's change over the acceleration window of {} samples{} and the "
      "controls' hold) is {:.2g}% of the force the controls apply on {} (at most {:g}%)",
      facts.acceleration_window, facts.acceleration_derivative == 2 ? " on the measured positions" : "",
      100.0 * facts.misfit, facts.misfit_state, 100.0 * kFilterMisfit);
  const std::string kept = fmt::format(
      "the acceleration window of {} samples keeps {:.0f}% of the motion of {} (the rms of its window means about "
      "its mean, against its own; at least {:g}%)",
      facts.acceleration_window, 100.0 * facts.motion_kept, facts.motion_kept_state, 100.0 * kMotionKept);
  // The filter follows the model: it keeps the motion and leaves little of a true model's equation.
  const bool follows = facts.motion_kept >= kMotionKept && facts.misfit <= kFilterMisfit;
  const std::string not_following = facts.motion_kept < kMotionKept ? kept : misfit;
  if (estimated) {
    if (follows) {
      choice.criterion = FitCriterion::InverseDynamics;
      choice.instruments = true;
      choice.reason = fmt::format(
          "inverse-dynamics in its instrumental-variable form (IDIM-IV): the controls are generalised forces, {}, "
          "{} and {}; the estimates' noise is filtered, so the bias it gives least squares cannot be bounded from "
          "the data, and the instruments, the model simulated with the measured controls, do not share it",
          estimated_why, kept, misfit);
      return choice;
    }
    return estimated_simulation("the controls are generalised forces, but " + not_following);
  }
  if (facts.ratio >= kInverseDynamicsRatio && !follows) {
    choice.reason = fmt::format(
        "one-step: the controls are generalised forces, the velocities are measured and the inverse-dynamics "
        "residual's error per sample would be {:.3g} times below the one-step residual's ({}), but {}",
        facts.ratio, measured, not_following);
    return choice;
  }
  if (facts.ratio >= kInverseDynamicsRatio) {
    choice.criterion = FitCriterion::InverseDynamics;
    for (const GeneralisedCoordinate& c : coordinates) {
      const double lambda = attenuation(data, c.velocity);
      if (lambda > facts.attenuation || facts.attenuation_state.empty()) {
        facts.attenuation = lambda;
        facts.attenuation_state = data.system.states[static_cast<std::size_t>(c.velocity)].name;
      }
    }
    choice.instruments = facts.attenuation >= kInstrumentAttenuation;
    const std::string form =
        choice.instruments
            ? fmt::format("; in its instrumental-variable form (IDIM-IV), since the noise of the measured {} is {:.2g}% "
                          "of its variance, the bias least squares would have ({:g}% or more)",
                          facts.attenuation_state, 100.0 * facts.attenuation, 100.0 * kInstrumentAttenuation)
            : fmt::format("; by least squares, since the noise of the measured velocities biases it by {:.2g}% at "
                          "most ({}; the instrumental-variable form from {:g}%)",
                          100.0 * facts.attenuation, facts.attenuation_state, 100.0 * kInstrumentAttenuation);
    choice.reason = fmt::format(
        "inverse-dynamics: the controls are generalised forces, the velocities are measured, and the "
        "inverse-dynamics residual's error per sample is {:.3g} times below the one-step residual's ({}; {:.0f} "
        "needed), {} and {}{}",
        facts.ratio, measured, kInverseDynamicsRatio, kept, misfit, form);
    return choice;
  }
  choice.reason = fmt::format(
      "one-step: the controls are generalised forces and the velocities are measured, but the inverse-dynamics "
      "residual's error per sample would be only {:.3g} times below the one-step residual's ({}; {:.0f} needed)",
      facts.ratio, measured, kInverseDynamicsRatio);
  return choice;
}

}  // namespace gpilqg::diagnosis
