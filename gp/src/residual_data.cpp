#include <cmath>
#include <sstream>
#include <stdexcept>

#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::gp {

TrainingSet ResidualData::output(int i) const {
  if (i < 0 || i >= residuals.cols())
    throw std::invalid_argument("ResidualData::output: index " + std::to_string(i) + " outside [0, " +
                                std::to_string(residuals.cols()) + ")");
  TrainingSet out{inputs, residuals.col(i)};
  if (noise_variance.size() > 0) out.noise_variance = noise_variance.col(i);
  return out;
}

ResidualData ResidualData::subset(const std::vector<int>& indices) const {
  ResidualData out;
  out.inputs.resize(static_cast<Eigen::Index>(indices.size()), inputs.cols());
  out.residuals.resize(static_cast<Eigen::Index>(indices.size()), residuals.cols());
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const int i = indices[k];
    if (i < 0 || i >= size())
      throw std::invalid_argument("ResidualData::subset: index " + std::to_string(i) + " outside [0, " +
                                  std::to_string(size()) + ")");
    out.inputs.row(static_cast<Eigen::Index>(k)) = inputs.row(i);
    out.residuals.row(static_cast<Eigen::Index>(k)) = residuals.row(i);
  }
  if (noise_variance.size() > 0) {
    out.noise_variance.resize(static_cast<Eigen::Index>(indices.size()), noise_variance.cols());
    for (std::size_t k = 0; k < indices.size(); ++k) out.noise_variance.row(static_cast<Eigen::Index>(k)) = noise_variance.row(indices[k]);
  }
  return out;
}

ResidualData make_residual_data(const StepModel& simulator, const MatrixCRef& x, const MatrixCRef& u,
                                const MatrixCRef& x_next) {
  const int n = simulator.state_dim(), m = simulator.control_dim();
  if (x.cols() != n || x_next.cols() != n || u.cols() != m || u.rows() != x.rows() || x_next.rows() != x.rows()) {
    std::ostringstream os;
    os << "make_residual_data: x is " << x.rows() << "x" << x.cols() << ", u " << u.rows() << "x" << u.cols()
       << ", x_next " << x_next.rows() << "x" << x_next.cols() << "; expected N x " << n << ", N x " << m << ", N x "
       << n << " for the simulator's " << n << " states and " << m << " controls";
    throw std::invalid_argument(os.str());
  }
  if (!x.allFinite() || !u.allFinite() || !x_next.allFinite())
    throw std::invalid_argument("make_residual_data: non-finite values in x, u or x_next; expected finite data");
  ResidualData data;
  data.inputs.resize(x.rows(), n + m);
  data.residuals.resize(x.rows(), n);
  Vector predicted(n);
  const auto workspace = simulator.make_workspace();
  for (Eigen::Index t = 0; t < x.rows(); ++t) {
    data.inputs.row(t).head(n) = x.row(t);
    data.inputs.row(t).tail(m) = u.row(t);
    simulator.step(x.row(t).transpose(), u.row(t).transpose(), predicted, nullptr, *workspace);
    data.residuals.row(t) = x_next.row(t) - predicted.transpose();
  }
  return data;
}

ResidualData make_residual_data(const StepModel& simulator, const MeasurementSet& measurements) {
  const int n = simulator.state_dim(), m = simulator.control_dim();
  const auto states = static_cast<int>(measurements.system.states.size());
  const auto controls = static_cast<int>(measurements.system.controls.size());
  if (states != n || controls != m)
    throw std::invalid_argument("make_residual_data: measurements of '" + measurements.system.name + "' have " +
                                std::to_string(states) + " states and " + std::to_string(controls) +
                                " controls; expected the simulator's " + std::to_string(n) + " and " +
                                std::to_string(m));
  Eigen::Index rows = 0;
  for (const Episode& e : measurements.episodes) rows += std::max(e.length() - 1, 0);
  Matrix x(rows, n), u(rows, m), x_next(rows, n);
  Eigen::Index row = 0;
  for (const Episode& e : measurements.episodes) {
    if (e.length() < 2) continue;
    const double dt = e.dt();
    if (!(std::abs(dt - simulator.dt()) <= 1e-6 * simulator.dt())) {
      std::ostringstream os;
      os.precision(17);
      os << "make_residual_data: episode " << e.id << " has dt = " << dt << " s; expected the simulator's dt = "
         << simulator.dt() << " s (within 1e-6 relative)";
      throw std::invalid_argument(os.str());
    }
    if (e.x.rows() != e.length() || e.u.rows() != e.length() || e.x.cols() != n || e.u.cols() != m)
      throw std::invalid_argument("make_residual_data: episode " + std::to_string(e.id) +
                                  " has inconsistent shapes of t, x and u");
    const Eigen::Index steps = e.length() - 1;
    x.middleRows(row, steps) = e.x.topRows(steps);
    u.middleRows(row, steps) = e.u.topRows(steps);
    x_next.middleRows(row, steps) = e.x.bottomRows(steps);
    row += steps;
  }
  if (rows == 0) throw std::invalid_argument("make_residual_data: no episode has two consecutive samples");
  return make_residual_data(simulator, x, u, x_next);
}

}  // namespace gpilqg::gp
