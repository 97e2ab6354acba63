#include "gpilqg/core/resampling.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gpilqg {

namespace {
/// A time within this share of a step of a grid point is on the grid point.
constexpr double kOnGrid = 1e-6;
}  // namespace

std::vector<SampleRange> split_at_gaps(const VectorCRef& t, double max_gap) {
  std::vector<SampleRange> ranges;
  if (t.size() == 0) return ranges;
  long begin = 0;
  for (long i = 1; i < t.size(); ++i) {
    const double step = t(i) - t(i - 1);
    if (!(step > 0.0)) throw std::invalid_argument("split_at_gaps: times must be strictly increasing");
    if (step > max_gap) {
      ranges.push_back({begin, i});
      begin = i;
    }
  }
  ranges.push_back({begin, static_cast<long>(t.size())});
  return ranges;
}

double uniform_grid_size(const VectorCRef& t, double dt) {
  if (t.size() == 0 || !(dt > 0.0)) throw std::invalid_argument("uniform_grid_size: needs samples and dt > 0");
  return std::floor((t(t.size() - 1) - t(0)) / dt + kOnGrid) + 1.0;
}

Vector uniform_grid(const VectorCRef& t, double dt) {
  if (t.size() == 0 || !(dt > 0.0)) throw std::invalid_argument("uniform_grid: needs samples and dt > 0");
  // A sample within a millionth of a step of a grid point is on it: a step computed from logged
  // times (66.600960 s + k 1.6384 ms) carries their rounding, which must not lose the last sample.
  const long steps = static_cast<long>(uniform_grid_size(t, dt)) - 1;
  Vector tau(steps + 1);
  for (long k = 0; k <= steps; ++k) tau(k) = t(0) + static_cast<double>(k) * dt;
  return tau;
}

namespace {

/// The index i of the last sample with t_i <= tau + tolerance (0 when tau precedes every sample).
long last_at_or_before(const VectorCRef& t, double tau, double tolerance = 0.0) {
  const auto* begin = t.data();
  const auto* end = t.data() + t.size();
  const auto* after = std::upper_bound(begin, end, tau + tolerance);
  return after == begin ? 0 : static_cast<long>(after - begin) - 1;
}

}  // namespace

Matrix interpolate_linear(const VectorCRef& t, const MatrixCRef& y, const VectorCRef& tau) {
  Matrix out(tau.size(), y.cols());
  const long last = static_cast<long>(t.size()) - 1;
  for (long k = 0; k < tau.size(); ++k) {
    const long i = std::min(last_at_or_before(t, tau(k)), std::max(last - 1, 0L));
    if (last == 0) {
      out.row(k) = y.row(0);
      continue;
    }
    const double w = (tau(k) - t(i)) / (t(i + 1) - t(i));
    out.row(k) = (1.0 - w) * y.row(i) + w * y.row(i + 1);
  }
  return out;
}

Matrix hold_zero_order(const VectorCRef& t, const MatrixCRef& y, const VectorCRef& tau) {
  Matrix out(tau.size(), y.cols());
  // A sample within a millionth of the grid's step of tau_k is at tau_k (the rounding of a grid built
  // from logged times would otherwise hold the previous sample's control at every point).
  const double tolerance = tau.size() >= 2 ? kOnGrid * (tau(1) - tau(0)) : 0.0;
  for (long k = 0; k < tau.size(); ++k) out.row(k) = y.row(last_at_or_before(t, tau(k), tolerance));
  return out;
}

Matrix average_held(const VectorCRef& t, const MatrixCRef& y, const VectorCRef& tau, double dt) {
  Matrix out = Matrix::Zero(tau.size(), y.cols());
  const long n = static_cast<long>(t.size());
  for (long k = 0; k < tau.size(); ++k) {
    const double end = tau(k) + dt;
    double a = tau(k);
    for (long i = last_at_or_before(t, a); a < end; ++i) {
      const double segment_end = i + 1 < n ? std::min(t(i + 1), end) : end;
      if (segment_end > a) out.row(k) += (segment_end - a) * y.row(i);
      a = std::max(a, segment_end);
      if (i + 1 >= n) break;
    }
    out.row(k) /= dt;
  }
  return out;
}

double median_step(const VectorCRef& t, const std::vector<SampleRange>& ranges) {
  std::vector<double> steps;
  for (const SampleRange& r : ranges)
    for (long i = r.begin + 1; i < r.end; ++i) steps.push_back(t(i) - t(i - 1));
  if (steps.empty()) return 0.0;
  const auto middle = steps.begin() + static_cast<long>(steps.size() / 2);
  std::nth_element(steps.begin(), middle, steps.end());
  if (steps.size() % 2 == 1) return *middle;
  const double upper = *middle;
  const double lower = *std::max_element(steps.begin(), middle);
  return 0.5 * (lower + upper);
}

}  // namespace gpilqg
