#include "gpilqg/experiments/diagnosis/accelerations.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/core/savitzky_golay.hpp"

namespace gpilqg::diagnosis {

std::vector<RowSegment> row_segments(const Transitions& data) {
  std::vector<RowSegment> out;
  for (int first = 0; first < data.size();) {
    const int episode = data.episode[static_cast<std::size_t>(first)];
    int end = first + 1;
    while (end < data.size() && data.episode[static_cast<std::size_t>(end)] == episode &&
           data.x_next.row(end - 1) == data.x.row(end))
      ++end;
    out.push_back({first, end, episode});
    first = end;
  }
  return out;
}

namespace {

/// The samples of state column `j` over `segment`: x_first .. x_{end-1}, then x_next_{end-1}.
Vector column_samples(const Transitions& data, const RowSegment& segment, int j) {
  Vector v(segment.samples());
  v.head(segment.end - segment.first) = data.x.col(j).segment(segment.first, segment.end - segment.first);
  v(v.size() - 1) = data.x_next(segment.end - 1, j);
  return v;
}

void check_time_steps(const Transitions& data, const RowSegment& segment, double dt) {
  if (data.t.size() != data.size()) return;  // no times recorded: the caller's dt stands
  for (int r = segment.first + 1; r < segment.end; ++r) {
    const double step = data.t(r) - data.t(r - 1);
    if (!(std::abs(step - dt) <= 1e-6 * dt))
      throw std::invalid_argument(fmt::format(
          "accelerations: episode {} steps from t = {} to t = {} ({} s); expected dt = {} s within 1e-6 relative",
          segment.episode, data.t(r - 1), data.t(r), step, dt));
  }
}

}  // namespace

AccelerationEstimate estimate_accelerations(const Transitions& data, const std::vector<int>& velocity_states, double dt,
                                            int order) {
  if (!(std::isfinite(dt) && dt > 0.0))
    throw std::invalid_argument(fmt::format("accelerations: dt = {}; expected a finite positive step", dt));
  for (const int j : velocity_states)
    if (j < 0 || j >= data.x.cols())
      throw std::invalid_argument(
          fmt::format("accelerations: velocity column {}; the state has {} columns", j, data.x.cols()));
  const std::vector<RowSegment> segments = row_segments(data);
  const int needed = shortest_differentiable_segment(order);
  for (const RowSegment& s : segments) {
    if (s.samples() < needed)
      throw std::invalid_argument(fmt::format(
          "accelerations: episode {} (rows {} to {}) has {} consecutive samples; the acceleration estimate needs at "
          "least {}", s.episode, s.first, s.end - 1, s.samples(), needed));
    check_time_steps(data, s, dt);
  }

  AccelerationEstimate out;
  out.velocity_states = velocity_states;
  out.order = order;
  out.qdd.resize(data.size(), static_cast<Eigen::Index>(velocity_states.size()));
  std::vector<std::vector<Vector>> samples(velocity_states.size());
  for (std::size_t k = 0; k < velocity_states.size(); ++k) {
    for (const RowSegment& s : segments) samples[k].push_back(column_samples(data, s, velocity_states[k]));
    out.windows.push_back(choose_derivative_window(samples[k], dt, order));
    out.window = std::max(out.window, out.windows.back().window);
  }
  if (velocity_states.empty()) return out;
  const SavitzkyGolayDerivative filter(out.window, order);
  for (std::size_t k = 0; k < velocity_states.size(); ++k)
    for (std::size_t s = 0; s < segments.size(); ++s) {
      const Vector derivative = filter.differentiate(samples[k][s], dt);
      const int rows = segments[s].end - segments[s].first;
      out.qdd.col(static_cast<Eigen::Index>(k)).segment(segments[s].first, rows) = derivative.head(rows);
    }
  return out;
}

Vector acceleration_weights(const SavitzkyGolayDerivative& filter, int position, ControlHold hold) {
  const int w = filter.window();
  const Vector& c = filter.weights(position);
  // k_s = sum_{j > s} c_j: the weight of the increment from sample s to s + 1 (s = 0 .. w-2).
  Vector k = Vector::Zero(w);  // k(w - 1) = 0: no increment leaves the last sample
  for (int s = w - 2; s >= 0; --s) k(s) = k(s + 1) + c(s + 1);
  if (hold == ControlHold::ZeroOrder) return k;
  Vector m(w);
  for (int r = 0; r < w; ++r) m(r) = 0.5 * (k(r) + (r > 0 ? k(r - 1) : 0.0));
  return m;
}

Matrix filtered_controls(const Transitions& data, const Matrix& u, int window, int order, ControlHold hold) {
  if (u.rows() != data.size())
    throw std::invalid_argument(
        fmt::format("filtered controls: {} rows of controls for {} transitions; expected one per transition", u.rows(),
                    data.size()));
  const SavitzkyGolayDerivative filter(window, order);
  std::vector<Vector> weights;
  for (int p = 0; p < window; ++p) weights.push_back(acceleration_weights(filter, p, hold));
  const int h = window / 2;
  Matrix out(u.rows(), u.cols());
  for (const RowSegment& s : row_segments(data)) {
    if (s.samples() < window)
      throw std::invalid_argument(fmt::format(
          "filtered controls: episode {} (rows {} to {}) has {} samples; the window spans {}", s.episode, s.first,
          s.end - 1, s.samples(), window));
    const int rows = s.end - s.first;
    for (int t = 0; t < rows; ++t) {
      // The window of sample t: centred, or the first / last w samples near the ends.
      const int start = std::clamp(t - h, 0, s.samples() - window);
      const Vector& m = weights[static_cast<std::size_t>(t - start)];
      auto row = out.row(s.first + t);
      row.setZero();
      for (int r = 0; r < window; ++r)  // the segment's last sample takes its last row's control
        row += m(r) * u.row(s.first + std::min(start + r, rows - 1));
    }
  }
  return out;
}

}  // namespace gpilqg::diagnosis
