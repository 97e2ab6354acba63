#pragma once
// Linear step models with noise and uncertainty columns linear in (x, u), for tests with exact answers:
//   x' = A x + B u,
//   noise columns       F = [ sigma_add * e_i (i in additive) | sigma_mul * u_j * b_j ]
//   uncertainty columns G = [ sigma_unc * u_j * b_j ]          (b_j = column j of B / dt)
// For such models the DDP value function is exactly quadratic, so iLQR reaches the Riccati solution in
// one step and the predicted expected cost of iLQG equals the true expected cost of its policy.

#include "gpilqg/core/step_model.hpp"

namespace gpilqg::test {

class LinearStepModel final : public StepModel {
 public:
  LinearStepModel(Matrix A, Matrix B, double dt) : A_(std::move(A)), B_(std::move(B)), dt_(dt) {}

  double additive_std = 0.0;        ///< constant column on every state
  double multiplicative_std = 0.0;  ///< control-dependent column per control
  double uncertainty_std = 0.0;     ///< control-dependent uncertainty column per control
  bool zero_uncertainty_columns = false;  ///< report G columns that are all zero (q = m)

  int state_dim() const override { return static_cast<int>(A_.rows()); }
  int control_dim() const override { return static_cast<int>(B_.cols()); }
  double dt() const override { return dt_; }

  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jac, StepWorkspace&) const override {
    x_next = A_ * x + B_ * u;
    if (jac) {
      jac->A = A_;
      jac->B = B_;
    }
  }

  int noise_dim() const override {
    return (additive_std > 0 ? state_dim() : 0) + (multiplicative_std > 0 ? control_dim() : 0);
  }
  using StepModel::noise;
  void noise(const VectorCRef&, const VectorCRef& u, DiffusionColumns& out, bool, StepWorkspace&) const override {
    const int n = state_dim(), m = control_dim();
    out.resize(n, m, noise_dim());
    int c = 0;
    if (additive_std > 0)
      for (int i = 0; i < n; ++i) out.columns(i, c++) = additive_std;
    if (multiplicative_std > 0)
      for (int j = 0; j < m; ++j, ++c) control_column(multiplicative_std, u, j, c, out);
  }

  int uncertainty_dim() const override {
    return (uncertainty_std > 0 || zero_uncertainty_columns) ? control_dim() : 0;
  }
  using StepModel::uncertainty;
  void uncertainty(const VectorCRef&, const VectorCRef& u, DiffusionColumns& out, bool, StepWorkspace&) const override {
    out.resize(state_dim(), control_dim(), uncertainty_dim());
    if (zero_uncertainty_columns) return;
    for (int j = 0; j < uncertainty_dim(); ++j) control_column(uncertainty_std, u, j, j, out);
  }

 private:
  /// Column c = sigma u_j b_j with d/du = sigma b_j e_j'.
  void control_column(double sigma, const VectorCRef& u, int j, int c, DiffusionColumns& out) const {
    const Vector b = B_.col(j) / dt_;
    out.columns.col(c) = sigma * u(j) * b;
    out.d_du[static_cast<std::size_t>(c)].col(j) = sigma * b;
  }

  Matrix A_, B_;
  double dt_;
};

}  // namespace gpilqg::test
