#include "gpilqg/core/effects.hpp"

#include <cmath>
#include <stdexcept>

namespace gpilqg {

namespace {

/// EffectDynamics' workspace: the base system's, and the buffers of the forces, so that a caller
/// that keeps it does not allocate per evaluation once warmed up.
struct EffectWorkspace final : DynamicsWorkspace {
  std::unique_ptr<DynamicsWorkspace> base;
  Vector u_applied;
  Vector Q;
  Matrix dQ_dx, dQ_du, W;
  std::vector<Matrix> dW;
};

}  // namespace

LinearForceEffect::LinearForceEffect(std::string name, EffectParameter parameter, std::string formula,
                                     int force_dim, Basis basis)
    : name_(std::move(name)), parameters_{std::move(parameter)}, formula_(std::move(formula)),
      force_dim_(force_dim), basis_(std::move(basis)) {
  if (name_.empty()) throw std::invalid_argument("LinearForceEffect: empty name");
  if (!basis_) throw std::invalid_argument("LinearForceEffect '" + name_ + "': null basis");
  if (force_dim_ < 1)
    throw std::invalid_argument("LinearForceEffect '" + name_ + "': force_dim = " + std::to_string(force_dim_) +
                                "; expected >= 1");
}

void LinearForceEffect::add_force(const VectorCRef& x, const VectorCRef&, const VectorCRef& theta, VectorRef Q,
                                  Matrix* dQ_dx, Matrix*) const {
  // Q += theta g(x);  dQ/dx += theta dg/dx;  dQ/du = 0.
  if (Q.size() != force_dim_)
    throw std::invalid_argument("LinearForceEffect '" + name_ + "': Q has " + std::to_string(Q.size()) +
                                " entries; expected " + std::to_string(force_dim_));
  basis_(x, theta(0), Q, dQ_dx);
}

EffectDynamics::EffectDynamics(DynamicsPtr base, double actuator_gain, std::vector<AppliedEffect> effects)
    : base_(std::move(base)), gain_(actuator_gain), effects_(std::move(effects)) {
  if (!base_) throw std::invalid_argument("EffectDynamics: null base system");
  if (!std::isfinite(gain_))
    throw std::invalid_argument("EffectDynamics: actuator gain " + std::to_string(gain_) + "; expected a finite value");
  forces_ = dynamic_cast<const GeneralisedForceInput*>(base_.get());
  for (const AppliedEffect& e : effects_) {
    if (!e.effect) throw std::invalid_argument("EffectDynamics: null effect");
    const auto expected = static_cast<Eigen::Index>(e.effect->parameters().size());
    if (e.theta.size() != expected || !e.theta.allFinite())
      throw std::invalid_argument("EffectDynamics: effect '" + e.effect->name() + "' has " +
                                  std::to_string(e.theta.size()) + " parameter values (finite: " +
                                  (e.theta.allFinite() ? "yes" : "no") + "); expected " + std::to_string(expected) +
                                  " finite values");
    if (forces_ == nullptr)
      throw std::invalid_argument("EffectDynamics: system '" + base_->name() +
                                  "' does not accept generalised forces, so effect '" + e.effect->name() +
                                  "' cannot be added");
    input_dependent_ = input_dependent_ || e.effect->depends_on_input();
  }
}

std::vector<Parameter> EffectDynamics::parameters() const {
  std::vector<Parameter> out = base_->parameters();
  out.push_back({"actuator_gain.k", "-", gain_});
  for (const AppliedEffect& e : effects_) {
    const auto& specs = e.effect->parameters();
    for (std::size_t i = 0; i < specs.size(); ++i)
      out.push_back({e.effect->name() + "." + specs[i].name, specs[i].unit, e.theta(static_cast<Eigen::Index>(i))});
  }
  return out;
}

std::unique_ptr<DynamicsWorkspace> EffectDynamics::make_workspace() const {
  auto workspace = std::make_unique<EffectWorkspace>();
  workspace->base = base_->make_workspace();
  return workspace;
}

void EffectDynamics::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                              DynamicsJacobians* jacobians) const {
  const auto workspace = make_workspace();
  evaluate(x, u, xdot, jacobians, *workspace);
}

void EffectDynamics::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot, DynamicsJacobians* jacobians,
                              DynamicsWorkspace& workspace) const {
  auto& s = workspace_as<EffectWorkspace>(workspace);
  s.u_applied = gain_ * u;
  base_->evaluate(x, s.u_applied, xdot, jacobians, *s.base);
  if (jacobians != nullptr) jacobians->fu *= gain_;
  if (effects_.empty()) return;

  const int n = state_dim(), m = control_dim();
  const auto k = static_cast<int>(forces_->generalised_forces().size());
  s.Q.setZero(k);
  if (jacobians != nullptr) {
    s.dQ_dx.setZero(k, n);
    s.dQ_du.setZero(k, m);
  }
  for (const AppliedEffect& e : effects_)
    e.effect->add_force(x, u, e.theta, s.Q, jacobians != nullptr ? &s.dQ_dx : nullptr,
                        jacobians != nullptr ? &s.dQ_du : nullptr, *s.base);
  forces_->generalised_force_map(x, s.W, jacobians != nullptr ? &s.dW : nullptr, *s.base);
  xdot.noalias() += s.W * s.Q;
  if (jacobians == nullptr) return;
  jacobians->fx.noalias() += s.W * s.dQ_dx;
  for (int j = 0; j < n; ++j) jacobians->fx.col(j).noalias() += s.dW[static_cast<std::size_t>(j)] * s.Q;
  jacobians->fu.noalias() += s.W * s.dQ_du;
}

void EffectDynamics::generalised_force(const VectorCRef& x, const VectorCRef& u, VectorRef Q,
                                       DynamicsWorkspace& workspace) const {
  auto& s = workspace_as<EffectWorkspace>(workspace);
  Q.setZero();
  for (const AppliedEffect& e : effects_) e.effect->add_force(x, u, e.theta, Q, nullptr, nullptr, *s.base);
}

void EffectDynamics::input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out) const {
  const auto workspace = make_workspace();
  input_matrix(x, u, out, *workspace);
}

void EffectDynamics::input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out,
                                  DynamicsWorkspace& workspace) const {
  if (input_dependent_) {
    Dynamics::input_matrix(x, u, out);
    return;
  }
  auto& s = workspace_as<EffectWorkspace>(workspace);
  s.u_applied = gain_ * u;
  base_->input_matrix(x, s.u_applied, out, *s.base);
  out.b *= gain_;
  for (auto& d : out.d_dx) d *= gain_;
  for (auto& d : out.d_du) d *= gain_ * gain_;
}

}  // namespace gpilqg
