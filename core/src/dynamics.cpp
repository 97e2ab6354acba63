#include "gpilqg/core/dynamics.hpp"

#include <algorithm>
#include <cmath>

namespace gpilqg {

void DynamicsJacobians::resize(int n, int m) {
  if (fx.rows() != n || fx.cols() != n) fx.resize(n, n);
  if (fu.rows() != n || fu.cols() != m) fu.resize(n, m);
}

void InputMatrix::resize(int n, int m) {
  if (b.rows() != n || b.cols() != m) b.resize(n, m);
  d_dx.resize(static_cast<std::size_t>(m));
  d_du.resize(static_cast<std::size_t>(m));
  for (auto& d : d_dx)
    if (d.rows() != n || d.cols() != n) d.resize(n, n);
  for (auto& d : d_du)
    if (d.rows() != n || d.cols() != m) d.resize(n, m);
}

std::unique_ptr<DynamicsWorkspace> Dynamics::make_workspace() const { return std::make_unique<DynamicsWorkspace>(); }

void Dynamics::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot, DynamicsJacobians* jacobians,
                        DynamicsWorkspace&) const {
  evaluate(x, u, xdot, jacobians);
}

void Dynamics::input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out, DynamicsWorkspace&) const {
  input_matrix(x, u, out);
}

Vector Dynamics::f(const VectorCRef& x, const VectorCRef& u) const {
  Vector xdot(state_dim());
  evaluate(x, u, xdot);
  return xdot;
}

void Dynamics::input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out) const {
  input_matrix_by_differences(x, u, out, nullptr);
}

void Dynamics::input_matrix_by_differences(const VectorCRef& x, const VectorCRef& u, InputMatrix& out,
                                           DynamicsWorkspace* workspace) const {
  const auto f = [&](const VectorCRef& xs, const VectorCRef& us, VectorRef xdot, DynamicsJacobians* jac) {
    if (workspace != nullptr) evaluate(xs, us, xdot, jac, *workspace);
    else evaluate(xs, us, xdot, jac);
  };
  // b = f_u from the (possibly analytic) Jacobian; its derivatives by central differences of f_u,
  // step h_k = 1e-6 max(1, |z_k|) (fu is itself a derivative, so the error is O(h^2) + O(eps/h)).
  const int n = state_dim();
  const int m = control_dim();
  out.resize(n, m);
  DynamicsJacobians jac;
  jac.resize(n, m);
  Vector xdot(n);
  f(x, u, xdot, &jac);
  out.b = jac.fu;

  Vector xp = x, up = u;
  DynamicsJacobians plus, minus;
  auto perturbed_fu = [&](DynamicsJacobians& into) { f(xp, up, xdot, &into); };
  for (int k = 0; k < n + m; ++k) {
    const bool is_state = k < n;
    double& entry = is_state ? xp(k) : up(k - n);
    const double original = entry;
    const double h = 1e-6 * std::max(1.0, std::abs(original));
    entry = original + h;
    perturbed_fu(plus);
    entry = original - h;
    perturbed_fu(minus);
    entry = original;
    for (int j = 0; j < m; ++j) {
      const Vector column = (plus.fu.col(j) - minus.fu.col(j)) / (2.0 * h);
      if (is_state)
        out.d_dx[static_cast<std::size_t>(j)].col(k) = column;
      else
        out.d_du[static_cast<std::size_t>(j)].col(k - n) = column;
    }
  }
}

void Dynamics::set_noise_model(ActuatorNoise noise) {
  noise.validate(state_dim(), control_dim());
  noise_ = std::move(noise);
}

void Dynamics::noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives) const {
  const auto workspace = make_workspace();
  noise(x, u, out, derivatives, *workspace);
}

void Dynamics::noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
                     DynamicsWorkspace& workspace) const {
  // Columns in the order of ActuatorNoise: additive actuator, multiplicative actuator, state.
  //   additive:        c = sa_j b_j            dc/dx = sa_j db_j/dx        dc/du = sa_j db_j/du
  //   multiplicative:  c = sm_j u_j b_j        dc/dx = sm_j u_j db_j/dx    dc/du = sm_j (u_j db_j/du + b_j e_j')
  //   state:           c = sx_i e_i            derivatives zero
  const int n = state_dim();
  const int m = control_dim();
  const int p = noise_dim();
  if (out.columns.rows() != n || out.count() != p || out.d_dx.size() != static_cast<std::size_t>(p) ||
      (p > 0 && out.d_du[0].cols() != m))
    out.resize(n, m, p);
  if (p == 0) return;

  const bool needs_b = noise_.additive_std.size() > 0 || noise_.multiplicative_std.size() > 0;
  InputMatrix& b = workspace.input;
  if (needs_b) input_matrix(x, u, b, workspace);

  int c = 0;
  for (Eigen::Index j = 0; j < noise_.additive_std.size(); ++j) {
    const double s = noise_.additive_std(j);
    if (s == 0.0) continue;
    out.columns.col(c) = s * b.b.col(j);
    if (derivatives) {
      out.d_dx[static_cast<std::size_t>(c)] = s * b.d_dx[static_cast<std::size_t>(j)];
      out.d_du[static_cast<std::size_t>(c)] = s * b.d_du[static_cast<std::size_t>(j)];
    }
    ++c;
  }
  for (Eigen::Index j = 0; j < noise_.multiplicative_std.size(); ++j) {
    const double s = noise_.multiplicative_std(j);
    if (s == 0.0) continue;
    out.columns.col(c) = s * u(j) * b.b.col(j);
    if (derivatives) {
      out.d_dx[static_cast<std::size_t>(c)] = (s * u(j)) * b.d_dx[static_cast<std::size_t>(j)];
      auto& du = out.d_du[static_cast<std::size_t>(c)];
      du = (s * u(j)) * b.d_du[static_cast<std::size_t>(j)];
      du.col(j) += s * b.b.col(j);
    }
    ++c;
  }
  for (Eigen::Index i = 0; i < noise_.state_std.size(); ++i) {
    const double s = noise_.state_std(i);
    if (s == 0.0) continue;
    out.columns.col(c).setZero();
    out.columns(i, c) = s;
    if (derivatives) {
      out.d_dx[static_cast<std::size_t>(c)].setZero();
      out.d_du[static_cast<std::size_t>(c)].setZero();
    }
    ++c;
  }
}

}  // namespace gpilqg
