#include "gpilqg/experiments/diagnosis/motion_period.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/derivative_window.hpp"

namespace gpilqg::diagnosis {

namespace {

/// Hysteresis crossings of one centred episode: their count and the samples of the first and last.
struct Crossings {
  long count = 0;
  long first = -1;
  long last = -1;
};

Crossings count_crossings(const Vector& centred, double band) {
  Crossings out;
  int side = 0;  // -1 below -band, +1 above +band, 0 not yet outside the band
  for (Eigen::Index i = 0; i < centred.size(); ++i) {
    const int now = centred(i) > band ? 1 : (centred(i) < -band ? -1 : 0);
    if (now == 0 || now == side) continue;
    if (side != 0) {
      ++out.count;
      if (out.first < 0) out.first = i;
      out.last = i;
    }
    side = now;
  }
  return out;
}

}  // namespace

MotionPeriod motion_period(const MeasurementSet& data, int state) {
  if (data.episodes.empty()) throw DataProblem("motion period: the measurement set has no episodes");
  const auto n = static_cast<int>(data.system.states.size());
  if (state < 0 || state >= n)
    throw std::invalid_argument(fmt::format("motion period: state column {} is outside the {} states", state, n));
  MotionPeriod out;
  out.state = state;
  std::vector<Vector> centred, noisy;
  double squares = 0.0;
  long samples = 0;
  for (const Episode& e : data.episodes) {
    const Vector column = e.x.col(state);
    if (column.size() == 0) continue;
    centred.push_back(column.array() - column.mean());
    squares += centred.back().squaredNorm();
    samples += column.size();
    if (column.size() >= 3) noisy.push_back(column);
  }
  out.band = noisy.empty() ? 0.0 : 3.0 * difference_noise_std(noisy);
  if (samples == 0 || std::sqrt(squares / static_cast<double>(samples)) <= out.band) {
    out.still = true;
    return out;
  }
  double span = 0.0;  // sum of (last - first) over episodes with at least two crossings [samples]
  long intervals = 0;
  for (const Vector& c : centred) {
    const Crossings crossings = count_crossings(c, out.band);
    out.crossings += crossings.count;
    if (crossings.count < 2) continue;
    span += static_cast<double>(crossings.last - crossings.first);
    intervals += crossings.count - 1;
  }
  const double dt = data.episodes.front().dt();
  out.period = intervals == 0 ? std::numeric_limits<double>::infinity()
                              : 2.0 * dt * span / static_cast<double>(intervals);
  return out;
}

}  // namespace gpilqg::diagnosis
