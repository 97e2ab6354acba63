#include "gpilqg/control/belief_space.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg {

namespace {

struct BeliefSpaceWorkspace final : StepWorkspace {
  std::unique_ptr<BeliefWorkspace> belief;
  BeliefJacobians jacobians;
};

struct BeliefCostWorkspace final : CostWorkspace {
  std::unique_ptr<CostWorkspace> cost;  ///< the state cost's workspace
  CostDerivatives state;                ///< the state cost's derivatives at the mean
};

}  // namespace

std::unique_ptr<StepWorkspace> BeliefSpaceModel::make_workspace() const {
  auto ws = std::make_unique<BeliefSpaceWorkspace>();
  ws->belief = belief_.make_workspace();
  return ws;
}

void BeliefSpaceModel::step(const VectorCRef& v, const VectorCRef& u, VectorRef v_next, StepJacobians* jacobians,
                            StepWorkspace& workspace) const {
  auto& ws = workspace_as<BeliefSpaceWorkspace>(workspace);
  if (!jacobians) {
    belief_.propagate(v, u, v_next, nullptr, *ws.belief);
    return;
  }
  belief_.propagate(v, u, v_next, &ws.jacobians, *ws.belief);
  jacobians->A = ws.jacobians.dv;
  jacobians->B = ws.jacobians.du;
}

BeliefCost::BeliefCost(const Cost& cost) : cost_(cost), n_(cost.state_dim()) {}

double BeliefCost::lift(double value, const CostDerivatives& state, const VectorCRef& v, CostDerivatives* d,
                        bool has_control) const {
  const int n = n_, nb = belief_dim(n_), m = has_control ? control_dim() : 0;
  // 0.5 tr(l_xx Sigma) over the packed entries, and its (constant) gradient.
  double trace = 0.0;
  if (d) {
    d->resize(nb, m);
    d->lx.setZero();
    d->lxx.setZero();
    d->lx.head(n) = state.lx;
    d->lxx.topLeftCorner(n, n) = state.lxx;
    if (has_control) {
      d->lu = state.lu;
      d->luu = state.luu;
      d->lux.setZero();
      d->lux.leftCols(n) = state.lux;
    }
  }
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) {
      const int k = n + vech_index(n, i, j);
      const double weight = i == j ? 0.5 * state.lxx(i, i) : 0.5 * (state.lxx(i, j) + state.lxx(j, i));
      trace += weight * v(k);
      if (d) d->lx(k) = weight;
    }
  if (d) d->value = value + trace;
  return value + trace;
}

std::unique_ptr<CostWorkspace> BeliefCost::make_workspace() const {
  auto ws = std::make_unique<BeliefCostWorkspace>();
  ws->cost = cost_.make_workspace();
  return ws;
}

double BeliefCost::stage(int t, const VectorCRef& v, const VectorCRef& u, CostDerivatives* d,
                         CostWorkspace& workspace) const {
  auto& ws = workspace_as<BeliefCostWorkspace>(workspace);
  const double value = cost_.stage(t, v.head(n_), u, &ws.state, *ws.cost);
  return lift(value, ws.state, v, d, true);
}

double BeliefCost::terminal(const VectorCRef& v, CostDerivatives* d, CostWorkspace& workspace) const {
  auto& ws = workspace_as<BeliefCostWorkspace>(workspace);
  const double value = cost_.terminal(v.head(n_), &ws.state, *ws.cost);
  return lift(value, ws.state, v, d, false);
}

double BeliefCost::terminal_at(int t, const VectorCRef& v, CostDerivatives* d, CostWorkspace& workspace) const {
  auto& ws = workspace_as<BeliefCostWorkspace>(workspace);
  const double value = cost_.terminal_at(t, v.head(n_), &ws.state, *ws.cost);
  return lift(value, ws.state, v, d, false);
}

PddpResult solve_pddp(const PddpProblem& problem, const Matrix& initial_controls, DdpOptions options) {
  if (problem.model == nullptr || problem.cost == nullptr) throw std::invalid_argument("pddp: no model or cost");
  const int n = problem.model->state_dim();
  if (problem.cost->state_dim() != n)
    throw std::invalid_argument("pddp: the cost has " + std::to_string(problem.cost->state_dim()) +
                                " states; the belief model " + std::to_string(n));
  if (problem.x0.size() != n) throw std::invalid_argument("pddp: x0 has " + std::to_string(problem.x0.size()) + " entries; expected " + std::to_string(n));
  const Matrix Sigma0 = problem.Sigma0.size() ? problem.Sigma0 : Matrix::Zero(n, n);
  if (Sigma0.rows() != n || Sigma0.cols() != n) throw std::invalid_argument("pddp: Sigma0 must be n x n");

  BeliefSpaceModel model(*problem.model);
  BeliefCost cost(*problem.cost);
  DdpProblem ddp;
  ddp.model = &model;
  ddp.cost = &cost;
  ddp.x0.resize(belief_dim(n));
  pack_belief(problem.x0, Sigma0, ddp.x0);
  ddp.horizon = problem.horizon;
  ddp.u_min = problem.u_min;
  ddp.u_max = problem.u_max;
  options.variant = DdpVariant::ILQR;
  DdpSolver solver(options);

  PddpResult out;
  out.belief = solver.solve(ddp, initial_controls);
  const int T = problem.horizon;
  out.mean.resize(n, T + 1);
  out.covariance.resize(static_cast<std::size_t>(T + 1));
  Vector mu;
  for (int t = 0; t <= T; ++t) {
    unpack_belief(out.belief.trajectory.x.col(t), n, mu, out.covariance[static_cast<std::size_t>(t)]);
    out.mean.col(t) = mu;
  }
  AffinePolicy& p = out.state_policy;
  p.x_bar = out.mean;
  p.u_bar = out.belief.trajectory.u;
  p.k = Matrix::Zero(p.u_bar.rows(), T);
  p.K.resize(static_cast<std::size_t>(T));
  for (int t = 0; t < T; ++t) p.K[static_cast<std::size_t>(t)] = out.belief.policy.K[static_cast<std::size_t>(t)].leftCols(n);
  p.u_min = out.belief.policy.u_min;
  p.u_max = out.belief.policy.u_max;
  return out;
}

}  // namespace gpilqg
