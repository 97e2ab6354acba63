#pragma once
// Synthetic training data drawn from the built-in systems for the GP benchmarks (pddp_bench.cpp,
// gp_bench.cpp): inputs z = [x; u] drawn uniformly from a box around each benchmark task, and fixed
// SE-ARD hyperparameters set from the data (no fitting is timed):
//   l_d = std of input column d,   sf = std of the output's targets,   sn = 0.01 sf.

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg::bench {

/// Lower and upper corners of the box of inputs z = [x; u].
struct InputBox {
  Vector low, high;
};

/// Cart-pole swing-up region: x, x_dot, theta, theta_dot, force.
inline InputBox cartpole_box() {
  InputBox box{Vector(5), Vector(5)};
  box.low << -1.5, -3.0, -0.5, -6.0, -10.0;
  box.high << 1.5, 3.0, 3.8, 6.0, 10.0;
  return box;
}

/// Hover thrust per rotor of the simulator quadrotor (mass 0.5 kg).
constexpr double kQuadrotorHover = 0.5 * 9.81 / 4.0;

/// Quadrotor flight from (0, 0, 5) to (4, 0, 5): p, v, r, w, and u around hover.
inline InputBox quadrotor_box() {
  InputBox box{Vector(16), Vector(16)};
  box.low << -0.5, -1.0, 4.0, -1.0, -1.0, -1.0, -0.2, -0.2, -0.2, -0.5, -0.5, -0.5,
      Vector::Constant(4, kQuadrotorHover - 0.5);
  box.high << 4.5, 1.0, 6.0, 2.0, 1.0, 1.0, 0.2, 0.2, 0.2, 0.5, 0.5, 0.5, Vector::Constant(4, kQuadrotorHover + 0.5);
  return box;
}

inline InputBox system_box(const std::string& system) { return system == "cartpole" ? cartpole_box() : quadrotor_box(); }

/// N points drawn uniformly from `box` (rows), from a fixed seed.
inline Matrix draw_inputs(const InputBox& box, int count, unsigned seed = 2024) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto D = box.low.size();
  Matrix inputs(count, D);
  for (int i = 0; i < count; ++i)
    for (Eigen::Index d = 0; d < D; ++d) inputs(i, d) = box.low(d) + (box.high(d) - box.low(d)) * unit(rng);
  return inputs;
}

/// Sample standard deviation of a column.
inline double sample_std(const Eigen::Ref<const Vector>& column) {
  return std::sqrt((column.array() - column.mean()).square().sum() / static_cast<double>(column.size() - 1));
}

/// [log l (D); log sf; log sn] per column of `targets`, as in the file comment.
inline std::vector<Vector> fixed_hyperparameters(const Matrix& inputs, const Matrix& targets) {
  const auto D = inputs.cols();
  std::vector<Vector> out;
  for (Eigen::Index a = 0; a < targets.cols(); ++a) {
    const double sf = sample_std(targets.col(a));
    Vector h(D + 2);
    for (Eigen::Index d = 0; d < D; ++d) h(d) = std::log(sample_std(inputs.col(d)));
    h(D) = std::log(sf);
    h(D + 1) = std::log(0.01 * sf);
    out.push_back(h);
  }
  return out;
}

}  // namespace gpilqg::bench
