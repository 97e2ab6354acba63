#include "gpilqg/core/cost.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

void CostDerivatives::resize(int n, int m) {
  if (lx.size() != n) lx.resize(n);
  if (lu.size() != m) lu.resize(m);
  if (lxx.rows() != n || lxx.cols() != n) lxx.resize(n, n);
  if (luu.rows() != m || luu.cols() != m) luu.resize(m, m);
  if (lux.rows() != m || lux.cols() != n) lux.resize(m, n);
}

namespace {

void check_weight(const Matrix& W, Eigen::Index size, const char* field) {
  if (W.rows() != size || W.cols() != size)
    throw std::invalid_argument(std::string("cost weight '") + field + "' is " +
                                std::to_string(W.rows()) + "x" + std::to_string(W.cols()) +
                                "; expected " + std::to_string(size) + "x" + std::to_string(size));
  if (!W.allFinite())
    throw std::invalid_argument(std::string("cost weight '") + field + "' has non-finite entries");
  const double scale = std::max(1.0, W.cwiseAbs().maxCoeff());
  if (((W - W.transpose()).cwiseAbs().array() > 1e-12 * scale).any())
    throw std::invalid_argument(std::string("cost weight '") + field + "' is not symmetric");
}

void check_reference(const Matrix& ref, Eigen::Index rows, Eigen::Index cols, const char* field) {
  if (ref.rows() != rows || ref.cols() != cols)
    throw std::invalid_argument(std::string("cost reference '") + field + "' is " +
                                std::to_string(ref.rows()) + "x" + std::to_string(ref.cols()) +
                                "; expected " + std::to_string(rows) + "x" + std::to_string(cols));
  if (!ref.allFinite())
    throw std::invalid_argument(std::string("cost reference '") + field + "' has non-finite entries");
}

}  // namespace

QuadraticCost::QuadraticCost(double dt, Matrix Q, Matrix R, Matrix Qf, Matrix x_ref, Matrix u_ref,
                             bool tracking)
    : dt_(dt),
      Q_(std::move(Q)),
      R_(std::move(R)),
      Qf_(std::move(Qf)),
      x_ref_(std::move(x_ref)),
      u_ref_(std::move(u_ref)),
      tracking_(tracking) {
  if (!std::isfinite(dt_) || dt_ <= 0.0)
    throw std::invalid_argument("cost dt = " + std::to_string(dt_) + "; expected a finite value > 0");
  const Eigen::Index n = Q_.rows(), m = R_.rows();
  check_weight(Q_, n, "Q");
  check_weight(R_, m, "R");
  check_weight(Qf_, n, "Qf");
  if (tracking_) {
    if (x_ref_.cols() < 2)
      throw std::invalid_argument("cost reference 'x_ref' has " + std::to_string(x_ref_.cols()) +
                                  " columns; expected T+1 >= 2");
    check_reference(x_ref_, n, x_ref_.cols(), "x_ref");
    check_reference(u_ref_, m, x_ref_.cols() - 1, "u_ref");
  } else {
    check_reference(x_ref_, n, 1, "goal");
    check_reference(u_ref_, m, 1, "u_ref");
  }
}

QuadraticCost::QuadraticCost(double dt, Matrix Q, Matrix R, Matrix Qf, Vector goal)
    : QuadraticCost(dt, std::move(Q), R, std::move(Qf), Matrix(goal), Matrix::Zero(R.rows(), 1),
                    false) {}

QuadraticCost QuadraticCost::tracking(double dt, Matrix Q, Matrix R, Matrix Qf, Matrix x_ref,
                                      Matrix u_ref) {
  return QuadraticCost(dt, std::move(Q), std::move(R), std::move(Qf), std::move(x_ref),
                       std::move(u_ref), true);
}

Eigen::Ref<const Vector> QuadraticCost::state_reference(int t) const {
  if (t < 0) throw std::out_of_range("state reference step " + std::to_string(t) + " is negative");
  if (!tracking_) return x_ref_.col(0);
  return x_ref_.col(std::min<Eigen::Index>(t, x_ref_.cols() - 1));
}

Eigen::Ref<const Vector> QuadraticCost::control_reference(int t) const {
  if (t < 0) throw std::out_of_range("control reference step " + std::to_string(t) + " is negative");
  if (!tracking_) return u_ref_.col(0);
  return u_ref_.col(std::min<Eigen::Index>(t, u_ref_.cols() - 1));
}

namespace {

/// 0.5 e'We with e = a - b, and W e into `gradient` when not null; entry by entry, so that nothing is
/// allocated (the cost is evaluated T times per pass).
double half_quadratic_form(const Matrix& W, const VectorCRef& a, const VectorCRef& b, Vector* gradient) {
  double value = 0.0;
  if (gradient != nullptr) gradient->setZero(a.size());
  for (Eigen::Index j = 0; j < W.cols(); ++j) {
    const double ej = a(j) - b(j);
    if (ej == 0.0) continue;
    for (Eigen::Index i = 0; i < W.rows(); ++i) {
      const double wij_ej = W(i, j) * ej;
      value += (a(i) - b(i)) * wij_ej;
      if (gradient != nullptr) (*gradient)(i) += wij_ej;
    }
  }
  return 0.5 * value;
}

}  // namespace

double Cost::stage(int t, const VectorCRef& x, const VectorCRef& u, CostDerivatives* derivatives) const {
  const auto workspace = make_workspace();
  return stage(t, x, u, derivatives, *workspace);
}

double Cost::terminal(const VectorCRef& x, CostDerivatives* derivatives) const {
  const auto workspace = make_workspace();
  return terminal(x, derivatives, *workspace);
}

double Cost::terminal_at(int t, const VectorCRef& x, CostDerivatives* derivatives) const {
  const auto workspace = make_workspace();
  return terminal_at(t, x, derivatives, *workspace);
}

double QuadraticCost::stage(int t, const VectorCRef& x, const VectorCRef& u, CostDerivatives* derivatives,
                            CostWorkspace&) const {
  const double value =
      dt_ * (half_quadratic_form(Q_, x, state_reference(t), derivatives ? &derivatives->lx : nullptr) +
             half_quadratic_form(R_, u, control_reference(t), derivatives ? &derivatives->lu : nullptr));
  if (derivatives) {
    derivatives->resize(state_dim(), control_dim());
    derivatives->value = value;
    derivatives->lx *= dt_;
    derivatives->lu *= dt_;
    derivatives->lxx = dt_ * Q_;
    derivatives->luu = dt_ * R_;
    derivatives->lux.setZero();
  }
  return value;
}

double QuadraticCost::terminal(const VectorCRef& x, CostDerivatives* derivatives, CostWorkspace& workspace) const {
  return terminal_at(tracking_ ? static_cast<int>(x_ref_.cols()) - 1 : 0, x, derivatives, workspace);
}

double QuadraticCost::terminal_at(int t, const VectorCRef& x, CostDerivatives* derivatives, CostWorkspace&) const {
  const double value = half_quadratic_form(Qf_, x, state_reference(t), derivatives ? &derivatives->lx : nullptr);
  if (derivatives) {
    derivatives->resize(state_dim(), 0);
    derivatives->value = value;
    derivatives->lxx = Qf_;
  }
  return value;
}

Matrix straight_line_reference(const VectorCRef& x0, const VectorCRef& goal, int horizon) {
  if (horizon < 1)
    throw std::invalid_argument("straight_line_reference: horizon = " + std::to_string(horizon) +
                                "; expected >= 1");
  if (x0.size() != goal.size())
    throw std::invalid_argument("straight_line_reference: x0 has " + std::to_string(x0.size()) +
                                " entries, goal " + std::to_string(goal.size()));
  Matrix ref(x0.size(), horizon + 1);
  for (int t = 0; t <= horizon; ++t)
    ref.col(t) = x0 + (static_cast<double>(t) / horizon) * (goal - x0);
  return ref;
}

}  // namespace gpilqg
