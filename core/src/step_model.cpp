#include "gpilqg/core/step_model.hpp"

namespace gpilqg {

void StepJacobians::resize(int n, int m) {
  if (A.rows() != n || A.cols() != n) A.resize(n, n);
  if (B.rows() != n || B.cols() != m) B.resize(n, m);
}

void StepModel::step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians) const {
  const auto workspace = make_workspace();
  step(x, u, x_next, jacobians, *workspace);
}

void StepModel::noise(const VectorCRef&, const VectorCRef&, DiffusionColumns& out, bool, StepWorkspace&) const {
  out.resize(state_dim(), control_dim(), 0);
}

void StepModel::noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives) const {
  const auto workspace = make_workspace();
  noise(x, u, out, derivatives, *workspace);
}

void StepModel::uncertainty(const VectorCRef&, const VectorCRef&, DiffusionColumns& out, bool,
                            StepWorkspace&) const {
  out.resize(state_dim(), control_dim(), 0);
}

void StepModel::uncertainty(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out,
                            bool derivatives) const {
  const auto workspace = make_workspace();
  uncertainty(x, u, out, derivatives, *workspace);
}

Vector StepModel::next(const VectorCRef& x, const VectorCRef& u) const {
  Vector x_next(state_dim());
  step(x, u, x_next);
  return x_next;
}

}  // namespace gpilqg
