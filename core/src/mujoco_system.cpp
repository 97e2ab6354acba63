#include "gpilqg/core/mujoco_system.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "gpilqg/core/effects.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "mujoco_model.hpp"

namespace gpilqg {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// What the passive-force callback needs during one step: the decorated system's forces, its
/// workspace (with an mjData of its own: the step's is busy) and buffers.
struct PassiveContext {
  const EffectDynamics* effects = nullptr;
  const Vector* gains = nullptr;  ///< k: the commanded input is ctrl ./ k
  DynamicsWorkspace* workspace = nullptr;
  Vector x, u, Q;
};

/// MuJoCo's passive-force callback (mjcb_passive, process-wide): adds the generalised forces of the
/// step's effects, Q(x, u), to qfrc_passive. The context pointer sits in the mjData's last userdata
/// slot; mjData without one (no effects) are left alone. Evaluated inside every mj_step and every
/// perturbed step of mjd_transitionFD, so A and B include dQ/dx.
void add_effect_forces(const mjModel* m, mjData* d) {
  const double slot = d->userdata[m->nuserdata - 1];
  PassiveContext* context = nullptr;
  std::memcpy(&context, &slot, sizeof context);
  if (context == nullptr) return;
  const int nv = m->nv;
  for (int i = 0; i < nv; ++i) {
    context->x(i) = d->qpos[i];
    context->x(nv + i) = d->qvel[i];
  }
  for (int a = 0; a < m->nu; ++a) {
    const double k = (*context->gains)(a);
    context->u(a) = k != 0.0 ? d->ctrl[a] / k : 0.0;
  }
  context->effects->generalised_force(context->x, context->u, context->Q, *context->workspace);
  for (int i = 0; i < nv; ++i) d->qfrc_passive[i] += context->Q(i);
}

void install_passive_callback() {
  static std::once_flag once;
  std::call_once(once, [] { mjcb_passive = add_effect_forces; });
}

/// The caller's scratch for steps of a MujocoStepModel.
struct MujocoStepWorkspace final : StepWorkspace {
  MujocoModel::DataPtr data;                  ///< the stepping mjData
  std::unique_ptr<DynamicsWorkspace> system;  ///< the decorated system's (noise, effect forces)
  PassiveContext context;
  RowMajorMatrix A_sub, B_sub;
  Matrix A_chain, B_chain;  ///< the products of the chain rule
};

/// Why a step of dt does not suit `model` (MujocoSystem::step_problem), or nothing.
std::optional<std::string> step_problem(const MujocoModel& model, double dt) {
  if (!std::isfinite(dt) || dt <= 0.0) return fmt::format("step length dt = {}; expected a finite value > 0", dt);
  const double timestep = model.m()->opt.timestep;
  const double ratio = dt / timestep;
  const long substeps = std::lround(ratio);
  if (substeps < 1 || std::abs(ratio - static_cast<double>(substeps)) > 1e-6 * ratio)
    return fmt::format("dt = {} s is not a whole multiple of the MuJoCo model's timestep {} s ({}); use a multiple such as {} s",
                       dt, timestep, model.path(), std::max(1L, substeps) * timestep);
  return std::nullopt;
}

/// The model's own integrator and timestep as a StepModel: dt / timestep calls of mj_step.
class MujocoStepModel final : public StepModel {
 public:
  MujocoStepModel(std::shared_ptr<const MujocoModel> model, DynamicsPtr decorated, double dt)
      : model_(std::move(model)), decorated_(std::move(decorated)), dt_(dt) {
    if (const std::optional<std::string> problem = step_problem(*model_, dt)) throw std::invalid_argument(*problem);
    substeps_ = static_cast<int>(std::lround(dt / model_->m()->opt.timestep));
    const auto* effects = dynamic_cast<const EffectDynamics*>(decorated_.get());
    gains_ = model_->gains();
    if (effects != nullptr) {
      gains_ *= effects->actuator_gain();
      if (!effects->effects().empty()) {
        for (const AppliedEffect& e : effects->effects())
          if (e.effect->depends_on_input())
            throw std::invalid_argument(fmt::format(
                "effect '{}' depends on the input; MuJoCo models take effects of the state only", e.effect->name()));
        effects_ = effects;
        install_passive_callback();
      }
    }
  }

  int state_dim() const override { return 2 * model_->nq(); }
  int control_dim() const override { return model_->nu(); }
  double dt() const override { return dt_; }

  std::unique_ptr<StepWorkspace> make_workspace() const override {
    auto ws = std::make_unique<MujocoStepWorkspace>();
    const int nv = model_->nq(), nu = model_->nu(), n = 2 * nv;
    ws->data = model_->make_data();
    ws->system = decorated_->make_workspace();
    ws->context = {effects_, &gains_, ws->system.get(), Vector(n), Vector(nu), Vector(nv)};
    ws->A_sub.resize(n, n);
    ws->B_sub.resize(n, nu);
    ws->A_chain.resize(n, n);
    ws->B_chain.resize(n, nu);
    return ws;
  }

  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians,
            StepWorkspace& workspace) const override {
    auto& ws = workspace_as<MujocoStepWorkspace>(workspace);
    const mjModel* m = model_->m();
    mjData* d = ws.data.get();
    const int nv = m->nv, n = 2 * nv, nu = m->nu;
    model_->prepare(d, x, u);
    for (int a = 0; a < nu; ++a) d->ctrl[a] = gains_(a) * u(a);
    if (effects_ != nullptr) {
      const PassiveContext* pointer = &ws.context;
      std::memcpy(&d->userdata[model_->context_slot()], &pointer, sizeof pointer);
    }
    if (jacobians != nullptr) {
      jacobians->resize(n, nu);
      jacobians->A.setIdentity();
      jacobians->B.setZero();
    }
    for (int s = 0; s < substeps_; ++s) {
      if (jacobians != nullptr) {
        // Centred differences with MuJoCo's own step; the state of d is restored afterwards.
        mjd_transitionFD(m, d, 1e-6, 1, ws.A_sub.data(), ws.B_sub.data(), nullptr, nullptr);
        ws.B_chain.noalias() = ws.A_sub * jacobians->B;
        ws.B_chain.noalias() += ws.B_sub * gains_.asDiagonal();
        jacobians->B = ws.B_chain;
        ws.A_chain.noalias() = ws.A_sub * jacobians->A;
        jacobians->A = ws.A_chain;
      }
      mj_step(m, d);
    }
    const bool unstable = d->warning[mjWARN_BADQACC].number > 0 || d->warning[mjWARN_BADQPOS].number > 0 ||
                          d->warning[mjWARN_BADQVEL].number > 0;
    for (int i = 0; i < nv; ++i) {
      x_next(i) = d->qpos[i];
      x_next(nv + i) = d->qvel[i];
    }
    // MuJoCo resets an unstable simulation to its initial state; report the divergence instead, as
    // the integrators do, so that rollouts record it as a status.
    if (unstable) x_next.setConstant(std::numeric_limits<double>::quiet_NaN());
  }

  int noise_dim() const override { return decorated_->noise_dim(); }
  using StepModel::noise;
  void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool derivatives,
             StepWorkspace& workspace) const override {
    decorated_->noise(x, u, out, derivatives, *workspace_as<MujocoStepWorkspace>(workspace).system);
  }

 private:
  std::shared_ptr<const MujocoModel> model_;
  DynamicsPtr decorated_;
  const EffectDynamics* effects_ = nullptr;
  Vector gains_;
  double dt_;
  int substeps_ = 1;
};

}  // namespace

MujocoSystem::MujocoSystem(std::shared_ptr<const MujocoModel> model) : model_(std::move(model)) {
  if (!model_) throw std::invalid_argument("MujocoSystem: null model");
}

std::shared_ptr<MujocoSystem> MujocoSystem::load(const std::string& path, const std::map<std::string, double>& overrides) {
  auto model = MujocoModel::load(path);
  if (!overrides.empty()) model = model->with_parameters(overrides);
  return std::make_shared<MujocoSystem>(std::move(model));
}

std::shared_ptr<MujocoSystem> MujocoSystem::with_parameters(const std::map<std::string, double>& overrides) const {
  return std::make_shared<MujocoSystem>(model_->with_parameters(overrides));
}

const std::string& MujocoSystem::name() const { return model_->name(); }
const std::vector<Quantity>& MujocoSystem::states() const { return model_->states(); }
const std::vector<Quantity>& MujocoSystem::controls() const { return model_->controls(); }
std::vector<Parameter> MujocoSystem::parameters() const { return model_->parameters(); }
const std::vector<Quantity>& MujocoSystem::generalised_forces() const { return model_->forces(); }
double MujocoSystem::timestep() const { return model_->m()->opt.timestep; }

std::optional<std::string> MujocoSystem::step_problem(double dt) const { return gpilqg::step_problem(*model_, dt); }
const std::string& MujocoSystem::path() const { return model_->path(); }
std::vector<std::string> MujocoSystem::body_names() const { return model_->body_names(); }
std::vector<std::string> MujocoSystem::joint_names() const { return model_->joint_names(); }
std::vector<std::string> MujocoSystem::actuator_names() const { return model_->actuator_names(); }

std::pair<Vector, Vector> MujocoSystem::control_limits() const {
  const mjModel* m = model_->m();
  const double inf = std::numeric_limits<double>::infinity();
  Vector lower = Vector::Constant(m->nu, -inf), upper = Vector::Constant(m->nu, inf);
  for (int a = 0; a < m->nu; ++a) {
    const double k = model_->gains()(a);
    if (!m->actuator_ctrllimited[a] || k <= 0.0) continue;
    lower(a) = m->actuator_ctrlrange[2 * a] / k;
    upper(a) = m->actuator_ctrlrange[2 * a + 1] / k;
  }
  return {lower, upper};
}

int MujocoSystem::joint_dof(const std::string& joint) const {
  const int id = mj_name2id(model_->m(), mjOBJ_JOINT, joint.c_str());
  return id < 0 ? -1 : model_->m()->jnt_dofadr[id];
}

std::unique_ptr<DynamicsWorkspace> MujocoSystem::make_workspace() const {
  auto ws = std::make_unique<MujocoWorkspace>();
  ws->data = model_->make_data();
  return ws;
}

void MujocoSystem::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                            DynamicsJacobians* jacobians) const {
  const auto workspace = make_workspace();
  evaluate(x, u, xdot, jacobians, *workspace);
}

void MujocoSystem::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot, DynamicsJacobians* jacobians,
                            DynamicsWorkspace& workspace) const {
  const mjModel* m = model_->m();
  mjData* d = workspace_as<MujocoWorkspace>(workspace).data.get();
  const int nv = m->nv;
  const auto f = [&](const VectorCRef& xs, const VectorCRef& us, VectorRef out) {
    model_->prepare(d, xs, us);
    mj_forward(m, d);
    for (int i = 0; i < nv; ++i) {
      out(i) = d->qvel[i];
      out(nv + i) = d->qacc[i];
    }
  };
  f(x, u, xdot);
  if (jacobians == nullptr) return;
  const Vector x0 = x, u0 = u;
  const int n = 2 * nv;
  jacobians->fx = central_difference_jacobian([&](const Vector& xs, Vector& out) { f(xs, u0, out); }, x0, n);
  jacobians->fu = central_difference_jacobian([&](const Vector& us, Vector& out) { f(x0, us, out); }, u0, n);
}

void MujocoSystem::generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const {
  const auto workspace = make_workspace();
  generalised_force_map(x, W, d_dx, *workspace);
}

void MujocoSystem::generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx,
                                         DynamicsWorkspace& workspace) const {
  const mjModel* m = model_->m();
  mjData* d = workspace_as<MujocoWorkspace>(workspace).data.get();
  const int nv = m->nv, n = 2 * nv;
  const Vector u0 = Vector::Zero(m->nu);
  const auto inverse_mass = [&](const Vector& xs) {
    model_->prepare(d, xs, u0);
    mj_fwdPosition(m, d);  // M(q) is a function of the positions: the position stage computes it
    RowMajorMatrix M(nv, nv);
    mj_fullM(m, M.data(), d->qM);
    return Matrix(M.llt().solve(Matrix::Identity(nv, nv)));
  };
  W.setZero(n, nv);
  W.bottomRows(nv) = inverse_mass(x);
  if (d_dx == nullptr) return;
  d_dx->assign(static_cast<std::size_t>(n), Matrix::Zero(n, nv));
  for (int j = 0; j < nv; ++j) {  // M depends on q only
    const double h = kCentralDifferenceStep * std::max(1.0, std::abs(x(j)));
    Vector plus = x, minus = x;
    plus(j) += h;
    minus(j) -= h;
    (*d_dx)[static_cast<std::size_t>(j)].bottomRows(nv) = (inverse_mass(plus) - inverse_mass(minus)) / (2.0 * h);
  }
}

bool MujocoSystem::inverse_dynamics_parts(const VectorCRef& x, const VectorCRef& u, const VectorCRef& qdd,
                                          VectorRef inertial, VectorRef forces, DynamicsWorkspace& workspace) const {
  const mjModel* m = model_->m();
  mjData* d = workspace_as<MujocoWorkspace>(workspace).data.get();
  const int nv = m->nv;
  model_->prepare(d, x, u);
  mj_fwdPosition(m, d);
  mj_mulM(m, d, inertial.data(), qdd.data());  // M qdd (both contiguous)
  if (d->nefc == 0) {  // the smooth forces are all: c - Q_passive - Q_actuator
    mj_fwdVelocity(m, d);
    mj_fwdActuation(m, d);
    for (int i = 0; i < nv; ++i) forces(i) = d->qfrc_bias[i] - d->qfrc_passive[i] - d->qfrc_actuator[i];
    return true;
  }
  // Constraint rows: the rest of the forward pass solves for their forces, then -M qacc.
  mj_forwardSkip(m, d, mjSTAGE_POS, 1);
  Vector& scratch = workspace_as<MujocoWorkspace>(workspace).scratch;
  scratch.resize(nv);
  mj_mulM(m, d, scratch.data(), d->qacc);
  forces = -scratch;
  return true;
}

bool MujocoSystem::control_forces(const VectorCRef& x, const VectorCRef& u, VectorRef Q,
                                  DynamicsWorkspace& workspace) const {
  const mjModel* m = model_->m();
  if (Q.size() != m->nv) return false;
  mjData* d = workspace_as<MujocoWorkspace>(workspace).data.get();
  model_->prepare(d, x, u);
  mj_fwdPosition(m, d);
  mj_fwdVelocity(m, d);
  mj_fwdActuation(m, d);
  for (int i = 0; i < m->nv; ++i) Q(i) = d->qfrc_actuator[i];
  return true;
}

std::shared_ptr<const StepModel> MujocoSystem::own_step_model(DynamicsPtr decorated, double dt) const {
  return std::make_shared<MujocoStepModel>(model_, std::move(decorated), dt);
}

}  // namespace gpilqg
