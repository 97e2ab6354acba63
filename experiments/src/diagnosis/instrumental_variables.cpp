#include "gpilqg/experiments/diagnosis/instrumental_variables.hpp"

#include <stdexcept>

#include <Eigen/QR>

#include "gpilqg/experiments/diagnosis/accelerations.hpp"
#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"

namespace gpilqg::diagnosis {

namespace {

/// One grid of simulation windows: the model simulated over the rows of every segment from the
/// measured state at rows first + offset + j W (and at the segment's first row), each row's simulated
/// state, next state, backward-difference acceleration and rows since its simulation started.
struct WindowGrid {
  Matrix x, x_next, qdd;
  std::vector<int> since_start;
  int restarts = 0;
};

WindowGrid simulate_grid(const StepModel& model, const Transitions& data, const Matrix& u,
                         const std::vector<int>& velocity, double dt, int window, int offset) {
  const auto k = static_cast<Eigen::Index>(velocity.size());
  WindowGrid g{data.x, data.x_next, Matrix::Zero(data.size(), k), std::vector<int>(static_cast<std::size_t>(data.size())), 0};
  const auto workspace = model.make_workspace();
  Vector x(model.state_dim()), next(model.state_dim()), previous(model.state_dim());
  for (const RowSegment& segment : row_segments(data)) {
    int since_start = 0;
    bool restart = true;
    for (int r = segment.first; r < segment.end; ++r, ++since_start) {
      if (restart || (r - segment.first - offset) % window == 0) {
        x = data.x.row(r).transpose();
        since_start = 0;
      }
      g.x.row(r) = x.transpose();
      g.since_start[static_cast<std::size_t>(r)] = since_start;
      if (since_start > 0)
        for (Eigen::Index i = 0; i < k; ++i) {
          const int v = velocity[static_cast<std::size_t>(i)];
          g.qdd(r, i) = (x(v) - previous(v)) / dt;
        }
      model.step(x, u.row(r).transpose(), next, nullptr, *workspace);
      restart = prediction_diverged(next);
      if (restart) {
        ++g.restarts;
        next = data.x_next.row(r).transpose();
      }
      g.x_next.row(r) = next.transpose();
      previous = x;
      x = next;
    }
  }
  return g;
}

}  // namespace

std::shared_ptr<const Instruments> simulated_instruments(const FitContext& c) {
  const InverseDynamicsCriterion* criterion = c.criterion->inverse_dynamics();
  if (criterion == nullptr)
    throw std::invalid_argument("instruments: the context is not an inverse-dynamics context (criterion_context)");
  if (c.data == nullptr) throw std::invalid_argument("instruments: the context has no data");
  const Transitions& data = *c.data;
  auto out = std::make_shared<Instruments>();
  out->reach = criterion->reach();
  out->window = 4 * (out->reach + 1);
  out->data = data;
  out->instrumented.assign(static_cast<std::size_t>(data.size()), false);

  const auto model = make_step_model(c.model, c.integrator, c.dt, c.substeps);
  const Matrix u = applied_controls(data, c.model.input_delay);
  const std::vector<int> velocity = force_components(*c.model.build()).velocity_states();
  // Two grids of windows, the second shifted by half a window: every row at least h + 1 rows into a
  // segment is more than h rows into a window of one of them, and takes the later-started of those.
  const WindowGrid a = simulate_grid(*model, data, u, velocity, c.dt, out->window, 0);
  const WindowGrid b = simulate_grid(*model, data, u, velocity, c.dt, out->window, out->window / 2);
  out->restarts = a.restarts + b.restarts;
  Matrix qdd(data.size(), static_cast<Eigen::Index>(velocity.size()));
  for (int r = 0; r < data.size(); ++r) {
    const int sa = a.since_start[static_cast<std::size_t>(r)], sb = b.since_start[static_cast<std::size_t>(r)];
    const bool a_usable = sa > out->reach, b_usable = sb > out->reach;
    const WindowGrid& g = a_usable && (!b_usable || sa <= sb) ? a : b;
    out->instrumented[static_cast<std::size_t>(r)] = a_usable || b_usable;
    out->data.x.row(r) = g.x.row(r);
    out->data.x_next.row(r) = g.x_next.row(r);
    qdd.row(r) = g.qdd.row(r);
  }
  out->accelerations = std::make_shared<const Matrix>(std::move(qdd));
  return out;
}

FitContext instrument_context(const FitContext& context) {
  const InverseDynamicsCriterion* criterion = context.criterion->inverse_dynamics();
  if (criterion == nullptr || criterion->instruments() == nullptr)
    throw std::invalid_argument("instrument_context: the context's criterion has no instruments");
  FitContext c = context;
  c.data = &criterion->instruments()->data;
  c.criterion = criterion->at_instruments();
  return c;
}

void zero_uninstrumented(Matrix& Z, const Instruments& instruments, const std::vector<int>& rows) {
  if (rows.empty()) return;
  const Eigen::Index k = Z.rows() / static_cast<Eigen::Index>(rows.size());
  for (std::size_t t = 0; t < rows.size(); ++t)
    if (!instruments.instrumented[static_cast<std::size_t>(rows[t])])
      Z.middleRows(static_cast<Eigen::Index>(t) * k, k).setZero();
}

Matrix instrument_basis(Matrix Z, const Instruments& instruments, const std::vector<int>& rows) {
  if (rows.empty() || Z.cols() == 0) return {};
  zero_uninstrumented(Z, instruments, rows);
  if (!Z.allFinite()) return {};
  const Eigen::ColPivHouseholderQR<Matrix> qr(Z);
  if (qr.rank() < Z.cols()) return {};
  return qr.householderQ() * Matrix::Identity(Z.rows(), Z.cols());
}

}  // namespace gpilqg::diagnosis
