#include "gpilqg/core/integrator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "gpilqg/core/effects.hpp"

namespace gpilqg {

std::optional<Integrator> parse_integrator(std::string_view name) {
  if (name == "euler") return Integrator::Euler;
  if (name == "rk4") return Integrator::RK4;
  return std::nullopt;
}

std::string_view to_string(Integrator integrator) {
  return integrator == Integrator::Euler ? "euler" : "rk4";
}

IntegratedStepModel::IntegratedStepModel(DynamicsPtr dynamics, Integrator integrator, double dt,
                                         int substeps)
    : dynamics_(std::move(dynamics)), integrator_(integrator), dt_(dt), substeps_(substeps) {
  if (!dynamics_) throw std::invalid_argument("IntegratedStepModel: dynamics is null");
  if (!std::isfinite(dt) || dt <= 0.0)
    throw std::invalid_argument("step length dt = " + std::to_string(dt) +
                                "; expected a finite value > 0");
  if (substeps < 1)
    throw std::invalid_argument("substeps = " + std::to_string(substeps) + "; expected >= 1");
}

/// The caller's scratch for steps of one IntegratedStepModel: the RK4 stages and their Jacobians, the
/// sub-step accumulation, and the dynamics' own workspace.
struct IntegratedStepModel::Workspace final : StepWorkspace {
  std::unique_ptr<DynamicsWorkspace> dynamics;
  Vector state;
  StepJacobians total, sub_step;
  Vector k1, k2, k3, k4, stage;
  DynamicsJacobians j1, j2, j3, j4;
  // Derivatives of the stages k_i with respect to the sub-step's initial state and control.
  Matrix dk1x, dk2x, dk3x, dk4x, dk1u, dk2u, dk3u, dk4u;
  StepJacobians sub;
  Matrix A_tmp, B_tmp;
  Vector x;

  void resize(int n, int m) {
    for (Vector* v : {&k1, &k2, &k3, &k4, &stage, &x})
      if (v->size() != n) v->resize(n);
    for (auto* j : {&j1, &j2, &j3, &j4}) j->resize(n, m);
    for (Matrix* a : {&dk1x, &dk2x, &dk3x, &dk4x, &A_tmp})
      if (a->rows() != n || a->cols() != n) a->resize(n, n);
    for (Matrix* b : {&dk1u, &dk2u, &dk3u, &dk4u, &B_tmp})
      if (b->rows() != n || b->cols() != m) b->resize(n, m);
    sub.resize(n, m);
  }
};

std::unique_ptr<StepWorkspace> IntegratedStepModel::make_workspace() const {
  auto ws = std::make_unique<Workspace>();
  ws->dynamics = dynamics_->make_workspace();
  ws->resize(state_dim(), control_dim());
  return ws;
}

void IntegratedStepModel::substep(Vector& x, const VectorCRef& u, double h, StepJacobians* jac,
                                  Workspace& ws) const {
  DynamicsWorkspace& dw = *ws.dynamics;
  const auto f_evaluate = [&](const VectorCRef& at, VectorRef xdot, DynamicsJacobians* j) {
    dynamics_->evaluate(at, u, xdot, j, dw);
  };

  if (integrator_ == Integrator::Euler) {
    // x' = x + h f(x, u);  A = I + h f_x;  B = h f_u
    f_evaluate(x, ws.k1, jac ? &ws.j1 : nullptr);
    if (jac) {
      jac->A.noalias() = h * ws.j1.fx;
      jac->A.diagonal().array() += 1.0;
      jac->B.noalias() = h * ws.j1.fu;
    }
    x += h * ws.k1;
    return;
  }

  // Classical RK4 with the control held over the sub-step.
  DynamicsJacobians* j1 = jac ? &ws.j1 : nullptr;
  DynamicsJacobians* j2 = jac ? &ws.j2 : nullptr;
  DynamicsJacobians* j3 = jac ? &ws.j3 : nullptr;
  DynamicsJacobians* j4 = jac ? &ws.j4 : nullptr;
  f_evaluate(x, ws.k1, j1);
  ws.stage = x + 0.5 * h * ws.k1;
  f_evaluate(ws.stage, ws.k2, j2);
  ws.stage = x + 0.5 * h * ws.k2;
  f_evaluate(ws.stage, ws.k3, j3);
  ws.stage = x + h * ws.k3;
  f_evaluate(ws.stage, ws.k4, j4);

  if (jac) {
    // Chain rule through the stages: stage_i = x + c_i h k_{i-1}, so
    //   dk_i/dx = fx_i (I + c_i h dk_{i-1}/dx),   dk_i/du = fx_i c_i h dk_{i-1}/du + fu_i.
    ws.dk1x = ws.j1.fx;
    ws.dk1u = ws.j1.fu;
    auto chain = [&](const DynamicsJacobians& ji, double c, const Matrix& prev_x, const Matrix& prev_u,
                     Matrix& out_x, Matrix& out_u) {
      ws.A_tmp = (c * h) * prev_x;
      ws.A_tmp.diagonal().array() += 1.0;
      out_x.noalias() = ji.fx * ws.A_tmp;
      out_u = ji.fu;
      out_u.noalias() += (c * h) * (ji.fx * prev_u);
    };
    chain(ws.j2, 0.5, ws.dk1x, ws.dk1u, ws.dk2x, ws.dk2u);
    chain(ws.j3, 0.5, ws.dk2x, ws.dk2u, ws.dk3x, ws.dk3u);
    chain(ws.j4, 1.0, ws.dk3x, ws.dk3u, ws.dk4x, ws.dk4u);
    const double w = h / 6.0;
    jac->A = w * (ws.dk1x + 2.0 * ws.dk2x + 2.0 * ws.dk3x + ws.dk4x);
    jac->A.diagonal().array() += 1.0;
    jac->B = w * (ws.dk1u + 2.0 * ws.dk2u + 2.0 * ws.dk3u + ws.dk4u);
  }
  x += (h / 6.0) * (ws.k1 + 2.0 * ws.k2 + 2.0 * ws.k3 + ws.k4);
}

void IntegratedStepModel::step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians,
                               StepWorkspace& workspace) const {
  const int n = state_dim();
  const int m = control_dim();
  const double h = dt_ / substeps_;
  if (jacobians) jacobians->resize(n, m);

  Workspace& ws = workspace_as<Workspace>(workspace);
  Vector& state = ws.state;
  StepJacobians& total = ws.total;
  StepJacobians& sub = ws.sub_step;
  state = x;
  if (substeps_ == 1) {
    substep(state, u, h, jacobians, ws);
    x_next = state;
    return;
  }
  // A = A_s ... A_1,  B = sum_k (A_s ... A_{k+1}) B_k, accumulated forwards.
  if (jacobians) {
    total.resize(n, m);
    sub.resize(n, m);
    total.A.setIdentity();
    total.B.setZero();
  }
  for (int s = 0; s < substeps_; ++s) {
    substep(state, u, h, jacobians ? &sub : nullptr, ws);
    if (jacobians) {
      jacobians->A.noalias() = sub.A * total.A;
      jacobians->B.noalias() = sub.A * total.B;
      jacobians->B += sub.B;
      total.A = jacobians->A;
      total.B = jacobians->B;
    }
  }
  x_next = state;
}

void IntegratedStepModel::noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
                                StepWorkspace& workspace) const {
  dynamics_->noise(x, u, out, derivatives, *workspace_as<Workspace>(workspace).dynamics);
}

}  // namespace gpilqg

namespace gpilqg {

const OwnIntegrator* own_integrator(const Dynamics& dynamics) {
  const Dynamics* system = &dynamics;
  if (const auto* decorated = dynamic_cast<const EffectDynamics*>(system)) system = &decorated->base();
  return dynamic_cast<const OwnIntegrator*>(system);
}

std::shared_ptr<const StepModel> make_step_model(DynamicsPtr dynamics, Integrator integrator, double dt,
                                                 int substeps) {
  if (!dynamics) throw std::invalid_argument("make_step_model: dynamics is null");
  if (const OwnIntegrator* own = own_integrator(*dynamics)) return own->own_step_model(dynamics, dt);
  return std::make_shared<IntegratedStepModel>(std::move(dynamics), integrator, dt, substeps);
}

}  // namespace gpilqg
