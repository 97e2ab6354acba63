#include "gpilqg/gp/noise_floor.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg::gp {

Matrix residual_noise_variance(const StepModel& simulator, const ResidualData& data, const VectorCRef& observation_std) {
  const int n = simulator.state_dim(), m = simulator.control_dim();
  if (data.inputs.cols() != n + m)
    throw std::invalid_argument("residual_noise_variance: data has " + std::to_string(data.inputs.cols()) +
                                " inputs; expected n + m = " + std::to_string(n + m));
  if (observation_std.size() != 0 && observation_std.size() != n)
    throw std::invalid_argument("residual_noise_variance: observation_std has " + std::to_string(observation_std.size()) +
                                " entries; expected " + std::to_string(n) + " (one per state) or none");
  if (observation_std.size() != 0 && !((observation_std.array() >= 0.0).all() && observation_std.allFinite()))
    throw std::invalid_argument("residual_noise_variance: observation_std must be finite and >= 0");

  const Vector sensor_variance =
      observation_std.size() != 0 ? Vector(observation_std.array().square()) : Vector(Vector::Zero(n));
  const auto workspace = simulator.make_workspace();
  StepJacobians jacobians;
  jacobians.resize(n, m);
  DiffusionColumns columns;
  Vector x_next(n);
  Matrix out(data.size(), n);
  for (int r = 0; r < data.size(); ++r) {
    const Vector z = data.inputs.row(r).transpose();
    Vector variance = sensor_variance;
    if (observation_std.size() != 0) {
      simulator.step(z.head(n), z.tail(m), x_next, &jacobians, *workspace);
      variance += jacobians.A.cwiseAbs2() * sensor_variance;
    }
    if (simulator.noise_dim() > 0) {
      simulator.noise(z.head(n), z.tail(m), columns, false, *workspace);
      variance += simulator.dt() * columns.columns.cwiseAbs2().rowwise().sum();
    }
    out.row(r) = variance.transpose();
  }
  return out;
}

Vector least_noise_std(const Matrix& noise_variance) {
  if (noise_variance.rows() == 0) return Vector::Zero(noise_variance.cols());
  return noise_variance.colwise().minCoeff().transpose().cwiseSqrt();
}

Vector sensor_noise_floor(const StepModel& simulator, const ResidualData& data, const VectorCRef& observation_std) {
  return least_noise_std(residual_noise_variance(simulator, data, observation_std));
}

}  // namespace gpilqg::gp
