#include "gpilqg/experiments/diagnosis/accelerations.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>

#include "gpilqg/core/savitzky_golay.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"

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
      throw DataProblem(fmt::format(
          "accelerations: episode {} steps from t = {} to t = {} ({} s); expected dt = {} s within 1e-6 relative",
          segment.episode, data.t(r - 1), data.t(r), step, dt));
  }
}

}  // namespace

DifferentiatedColumns differentiated_columns(const std::vector<int>& position_of, const std::vector<int>& velocity_states) {
  DifferentiatedColumns out{velocity_states, 1};
  if (velocity_states.empty() || position_of.empty()) return out;
  std::vector<int> positions;
  for (const int v : velocity_states) {
    const int position = v >= 0 && v < static_cast<int>(position_of.size()) ? position_of[static_cast<std::size_t>(v)] : -1;
    if (position < 0) return out;
    positions.push_back(position);
  }
  return {positions, 2};
}

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
      throw DataProblem(fmt::format(
          "accelerations: episode {} (rows {} to {}) has {} consecutive samples; the acceleration estimate needs at "
          "least {}", s.episode, s.first, s.end - 1, s.samples(), needed));
    check_time_steps(data, s, dt);
  }

  AccelerationEstimate out;
  out.velocity_states = velocity_states;
  const DifferentiatedColumns columns = differentiated_columns(data.position_of, velocity_states);
  out.differentiated_states = columns.states;
  out.derivative = columns.derivative;
  out.order = order;
  out.qdd.resize(data.size(), static_cast<Eigen::Index>(velocity_states.size()));
  std::vector<std::vector<Vector>> samples(velocity_states.size());
  for (std::size_t k = 0; k < velocity_states.size(); ++k) {
    for (const RowSegment& s : segments) samples[k].push_back(column_samples(data, s, columns.states[k]));
    out.windows.push_back(choose_derivative_window(samples[k], dt, order, columns.derivative));
    out.window = std::max(out.window, out.windows.back().window);
  }
  if (velocity_states.empty()) return out;
  const SavitzkyGolayDerivative filter(out.window, order, columns.derivative);
  for (std::size_t k = 0; k < velocity_states.size(); ++k)
    for (std::size_t s = 0; s < segments.size(); ++s) {
      const Vector derivative = filter.differentiate(samples[k][s], dt);
      const int rows = segments[s].end - segments[s].first;
      out.qdd.col(static_cast<Eigen::Index>(k)).segment(segments[s].first, rows) = derivative.head(rows);
    }
  return out;
}

namespace {

/// acceleration_weights of a second derivative of positions (header): m_r = sum_k c_k beta_{k,r}.
Vector position_acceleration_weights(const Vector& c, ControlHold hold) {
  const auto w = static_cast<int>(c.size());
  Vector m = Vector::Zero(w);
  for (int k = 1; k < w; ++k) {
    if (hold == ControlHold::ZeroOrder) {
      for (int r = 0; r < k; ++r) m(r) += c(k) * (k - r - 0.5);
      continue;
    }
    m(0) += c(k) * (0.5 * k - 1.0 / 6.0);
    for (int r = 1; r < k; ++r) m(r) += c(k) * (k - r);
    m(k) += c(k) / 6.0;
  }
  return m;
}

}  // namespace

Vector acceleration_weights(const SavitzkyGolayDerivative& filter, int position, ControlHold hold) {
  const int w = filter.window();
  const Vector& c = filter.weights(position);
  if (filter.derivative() == 2) return position_acceleration_weights(c, hold);
  // k_s = sum_{j > s} c_j: the weight of the increment from sample s to s + 1 (s = 0 .. w-2).
  Vector k = Vector::Zero(w);  // k(w - 1) = 0: no increment leaves the last sample
  for (int s = w - 2; s >= 0; --s) k(s) = k(s + 1) + c(s + 1);
  if (hold == ControlHold::ZeroOrder) return k;
  Vector m(w);
  for (int r = 0; r < w; ++r) m(r) = 0.5 * (k(r) + (r > 0 ? k(r - 1) : 0.0));
  return m;
}

namespace {

/// acceleration_weights of every position of the window of `filter` (index: the sample's place in
/// its window), made once per filter and hold: for a second derivative over w samples they cost
/// O(w^3), and a diagnosis filters thousands of times with one filter.
std::shared_ptr<const std::vector<Vector>> window_weights(const AccelerationFilter& filter, ControlHold hold) {
  static std::mutex mutex;
  static std::map<std::tuple<int, int, int, ControlHold>, std::shared_ptr<const std::vector<Vector>>> made;
  const auto key = std::make_tuple(filter.window, filter.order, filter.derivative, hold);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto found = made.find(key); found != made.end()) return found->second;
  }
  const SavitzkyGolayDerivative fit(filter.window, filter.order, filter.derivative);
  auto weights = std::make_shared<std::vector<Vector>>();
  for (int p = 0; p < filter.window; ++p) weights->push_back(acceleration_weights(fit, p, hold));
  const std::lock_guard<std::mutex> lock(mutex);
  return made.emplace(key, std::move(weights)).first->second;
}

}  // namespace

Matrix filtered_at(const Transitions& data, const Matrix& y, const std::vector<int>& rows,
                   const AccelerationFilter& acceleration_filter, ControlHold hold) {
  if (y.rows() != data.size())
    throw std::invalid_argument(fmt::format(
        "filtered signal: {} rows for {} transitions; expected one per transition", y.rows(), data.size()));
  const int window = acceleration_filter.window;
  const std::shared_ptr<const std::vector<Vector>> made = window_weights(acceleration_filter, hold);
  const std::vector<Vector>& weights = *made;
  const int h = window / 2;
  // The segment of every row, and each segment's samples of every column: its rows' values and, for
  // the last sample (x_next of its last row), the last row's value again.
  const std::vector<RowSegment> segments = row_segments(data);
  std::vector<int> segment_of(static_cast<std::size_t>(data.size()), -1);
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (segments[s].samples() < window)
      throw DataProblem(fmt::format(
          "filtered signal: episode {} (rows {} to {}) has {} samples; the window spans {}", segments[s].episode,
          segments[s].first, segments[s].end - 1, segments[s].samples(), window));
    for (int t = segments[s].first; t < segments[s].end; ++t) segment_of[static_cast<std::size_t>(t)] = static_cast<int>(s);
  }
  std::vector<Matrix> samples(segments.size());
  Matrix out(static_cast<Eigen::Index>(rows.size()), y.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int t = rows[i];
    if (t < 0 || t >= data.size())
      throw std::invalid_argument(fmt::format("filtered signal: row {}; the data have {} transitions", t, data.size()));
    const auto s = static_cast<std::size_t>(segment_of[static_cast<std::size_t>(t)]);
    const RowSegment& segment = segments[s];
    Matrix& column_samples = samples[s];
    if (column_samples.size() == 0) {
      const int n = segment.end - segment.first;
      column_samples.resize(n + 1, y.cols());
      column_samples.topRows(n) = y.middleRows(segment.first, n);
      column_samples.row(n) = y.row(segment.end - 1);
    }
    // The window of sample t: centred, or the first / last w samples near the ends.
    const int place = t - segment.first;
    const int start = std::clamp(place - h, 0, segment.samples() - window);
    const Vector& m = weights[static_cast<std::size_t>(place - start)];
    for (Eigen::Index j = 0; j < y.cols(); ++j)
      out(static_cast<Eigen::Index>(i), j) = m.dot(column_samples.col(j).segment(start, window));
  }
  return out;
}

Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> standstill_rows(const Transitions& data,
                                                                   const std::vector<int>& velocity_states,
                                                                   const AccelerationFilter& filter) {
  const auto c = static_cast<Eigen::Index>(velocity_states.size());
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> out =
      Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>::Constant(data.size(), c, false);
  if (filter.window < 1 || data.size() == 0) return out;
  const std::vector<RowSegment> segments = row_segments(data);
  const int h = filter.window / 2;
  for (Eigen::Index k = 0; k < c; ++k) {
    std::vector<Vector> samples;
    for (const RowSegment& s : segments) samples.push_back(column_samples(data, s, velocity_states[static_cast<std::size_t>(k)]));
    double squares = 0.0;
    long count = 0;
    for (const Vector& v : samples) {
      squares += v.squaredNorm();
      count += v.size();
    }
    const double rms = std::sqrt(squares / std::max(1L, count));
    const double band = kStandstillSpeed * rms;
    for (std::size_t s = 0; s < segments.size(); ++s) {
      const Vector& v = samples[s];
      const auto n = static_cast<int>(v.size());
      if (n < filter.window) continue;
      // outside[j]: samples before j outside the band; a window holds none when the count does not change.
      std::vector<int> outside(static_cast<std::size_t>(n) + 1, 0);
      for (int j = 0; j < n; ++j) outside[static_cast<std::size_t>(j) + 1] = outside[static_cast<std::size_t>(j)] + (std::abs(v(j)) > band ? 1 : 0);
      for (int t = segments[s].first; t < segments[s].end; ++t) {
        const int start = std::clamp(t - segments[s].first - h, 0, n - filter.window);
        out(t, k) = outside[static_cast<std::size_t>(start + filter.window)] == outside[static_cast<std::size_t>(start)];
      }
    }
  }
  return out;
}

Matrix filtered_controls(const Transitions& data, const Matrix& u, const AccelerationFilter& filter, ControlHold hold) {
  std::vector<int> rows(static_cast<std::size_t>(data.size()));
  for (std::size_t t = 0; t < rows.size(); ++t) rows[t] = static_cast<int>(t);
  return filtered_at(data, u, rows, filter, hold);
}

}  // namespace gpilqg::diagnosis
