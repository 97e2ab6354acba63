#include "gpilqg/experiments/model_slice.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {
namespace {

/// At most this many measured inputs are tried as the slice's base point (evenly spread over the
/// rows), so the choice costs O(kBaseCandidates N D) however much data there is.
constexpr int kBaseCandidates = 1000;
constexpr int kPoints = 401;

/// The output whose GP has the largest signal variance sf^2.
int largest_signal_output(const gp::ResidualModel& model) {
  int output = 0;
  double best = -1.0;
  for (int i = 0; i < model.state_dim(); ++i) {
    const double sf2 = model.output(i).prior_variance();
    if (sf2 > best) best = sf2, output = i;
  }
  return output;
}

/// The input with the shortest length-scale relative to the data's standard deviation in it: the
/// direction in which the GP varies most over the data.
int most_relevant_input(const Matrix& z, const Vector& l) {
  const Vector mean = z.colwise().mean().transpose();
  const Vector spread =
      ((z.rowwise() - mean.transpose()).cwiseAbs2().colwise().mean().cwiseSqrt().transpose().array() + 1e-9).matrix();
  Eigen::Index input = 0;
  (l.array() / spread.array()).minCoeff(&input);
  return static_cast<int>(input);
}

/// Whether row r of z lies within one length-scale of `base` in every input but `input`:
/// sum_{k != input} ((z_rk - base_k) / l_k)^2 <= 1.
bool near_slice(const Matrix& z, int r, const Vector& base, const Vector& l, int input) {
  double distance2 = 0.0;
  for (int k = 0; k < z.cols(); ++k)
    if (k != input) distance2 += std::pow((z(r, k) - base(k)) / l(k), 2);
  return distance2 <= 1.0;
}

/// The row of z with the most rows near the slice through it (ties: the first).
int densest_row(const Matrix& z, const Vector& l, int input) {
  const int rows = static_cast<int>(z.rows());
  const int stride = std::max(1, (rows + kBaseCandidates - 1) / kBaseCandidates);
  int best_row = 0, best_count = -1;
  for (int c = 0; c < rows; c += stride) {
    const Vector base = z.row(c).transpose();
    int count = 0;
    for (int r = 0; r < rows; ++r) count += near_slice(z, r, base, l, input) ? 1 : 0;
    if (count > best_count) best_count = count, best_row = c;
  }
  return best_row;
}

}  // namespace

ModelSlice model_slice(const StepModel& world, const StepModel& model, const TransitionData& data) {
  const auto* residual = dynamic_cast<const gp::ResidualModel*>(&model);
  if (residual == nullptr) throw std::invalid_argument("model_slice: the model is not a GP residual model");
  const int n = residual->state_dim(), m = residual->control_dim(), D = n + m;
  if (data.size() == 0) throw std::invalid_argument("model_slice: there are no measurements");
  if (data.x.cols() != n || data.u.cols() != m || data.x_next.cols() != n || data.u.rows() != data.size() ||
      data.x_next.rows() != data.size())
    throw std::invalid_argument("model_slice: the measurements have other dimensions than the model (" +
                                std::to_string(n) + " states, " + std::to_string(m) + " controls)");
  Matrix z(data.size(), D);
  z << data.x, data.u;

  ModelSlice s;
  s.output = largest_signal_output(*residual);
  s.length_scales = residual->output(s.output).parameters().head(D).array().exp().matrix();
  const Vector& l = s.length_scales;
  s.input = most_relevant_input(z, l);
  s.base = z.row(densest_row(z, l, s.input)).transpose();

  const double lo = z.col(s.input).minCoeff(), hi = z.col(s.input).maxCoeff();
  const double margin = kSliceMargin * l(s.input);
  s.grid = Vector::LinSpaced(kPoints, lo - margin, hi + margin);
  s.simulator.resize(kPoints), s.mean.resize(kPoints), s.std.resize(kPoints), s.truth.resize(kPoints);
  Vector x_next(n);
  DiffusionColumns columns;
  const auto simulator_ws = residual->simulator().make_workspace();
  const auto residual_ws = residual->make_workspace();
  const auto world_ws = world.make_workspace();
  for (int p = 0; p < kPoints; ++p) {
    Vector zp = s.base;
    zp(s.input) = s.grid(p);
    residual->simulator().step(zp.head(n), zp.tail(m), x_next, nullptr, *simulator_ws);
    s.simulator(p) = x_next(s.output);
    residual->step(zp.head(n), zp.tail(m), x_next, nullptr, *residual_ws);
    s.mean(p) = x_next(s.output);
    world.step(zp.head(n), zp.tail(m), x_next, nullptr, *world_ws);
    s.truth(p) = x_next(s.output);
    residual->uncertainty(zp.head(n), zp.tail(m), columns, false, *residual_ws);
    // G_ii = sqrt(var / dt) (residual_model.hpp), so the per-step std is G_ii sqrt(dt).
    s.std(p) = columns.columns(s.output, s.output) * std::sqrt(residual->dt());
  }

  std::vector<double> zs, ys, rs;
  for (int r = 0; r < data.size(); ++r) {
    if (!near_slice(z, r, s.base, l, s.input)) continue;
    residual->simulator().step(data.x.row(r).transpose(), data.u.row(r).transpose(), x_next, nullptr, *simulator_ws);
    zs.push_back(z(r, s.input));
    ys.push_back(data.x_next(r, s.output));
    rs.push_back(data.x_next(r, s.output) - x_next(s.output));
  }
  const auto as_vector = [](const std::vector<double>& v) {
    return Vector(Eigen::Map<const Vector>(v.data(), static_cast<Eigen::Index>(v.size())));
  };
  s.data_z = as_vector(zs), s.data_y = as_vector(ys), s.data_residual = as_vector(rs);
  return s;
}

}  // namespace gpilqg
