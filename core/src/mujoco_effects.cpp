/// The generic effect library of MuJoCo models
/// (docs/own-system.md#3-diagnosis-what-is-the-model-missing) and their registry entries.

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/core/effect_builders.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "gpilqg/core/mujoco_system.hpp"
#include "mujoco_model.hpp"

namespace gpilqg {
namespace {

/// external_force_<axis>:<body>: a constant world-frame force F e_axis at the body's centre of mass,
///
///   Q(q) = F J_com(q)' e_axis     (nv generalised forces; J_com the 3 x nv Jacobian of the centre),
///
/// linear in F; dQ/dq by central differences of J_com.
class BodyForceEffect final : public ForceEffect {
 public:
  BodyForceEffect(std::shared_ptr<const MujocoModel> model, int body, int axis, std::string name, std::string formula)
      : model_(std::move(model)), body_(body), axis_(axis), name_(std::move(name)), formula_(std::move(formula)),
        parameters_{{"F", "N", 1.0}} {}

  const std::string& name() const override { return name_; }
  const std::vector<EffectParameter>& parameters() const override { return parameters_; }
  const std::string& formula() const override { return formula_; }
  bool linear_in_parameters() const override { return true; }

  void add_force(const VectorCRef& x, const VectorCRef& u, const VectorCRef& theta, VectorRef Q, Matrix* dQ_dx,
                 Matrix* dQ_du) const override {
    MujocoWorkspace workspace;
    workspace.data = model_->make_data();
    add_force(x, u, theta, Q, dQ_dx, dQ_du, workspace);
  }

  /// `workspace` is the MuJoCo system's: its mjData holds the kinematics.
  void add_force(const VectorCRef& x, const VectorCRef&, const VectorCRef& theta, VectorRef Q, Matrix* dQ_dx, Matrix*,
                 DynamicsWorkspace& workspace) const override {
    mjData* d = workspace_as<MujocoWorkspace>(workspace).data.get();
    const int nv = model_->nq();
    Q.noalias() += theta(0) * basis(x, d);
    if (dQ_dx == nullptr) return;
    for (int j = 0; j < nv; ++j) {
      const double h = kCentralDifferenceStep * std::max(1.0, std::abs(x(j)));
      Vector plus = x, minus = x;
      plus(j) += h;
      minus(j) -= h;
      dQ_dx->col(j).noalias() += theta(0) * (basis(plus, d) - basis(minus, d)) / (2.0 * h);
    }
  }

 private:
  /// J_com(q)' e_axis, with the kinematics computed in d.
  Vector basis(const VectorCRef& x, mjData* d) const {
    const mjModel* m = model_->m();
    model_->prepare(d, x, Vector::Zero(m->nu));
    mj_kinematics(m, d);
    mj_comPos(m, d);
    std::vector<mjtNum> jacp(static_cast<std::size_t>(3 * m->nv));
    mj_jacBodyCom(m, d, jacp.data(), nullptr, body_);
    Vector g(m->nv);
    for (int i = 0; i < m->nv; ++i) g(i) = jacp[static_cast<std::size_t>(axis_ * m->nv + i)];
    return g;
  }

  std::shared_ptr<const MujocoModel> model_;
  int body_;
  int axis_;
  std::string name_;
  std::string formula_;
  std::vector<EffectParameter> parameters_;
};

/// The typical size of a field that may be zero in the file: sets the finite-difference step and
/// the search box of its recalibration.
double typical_scale(const std::string& field, double value) {
  double floor = 1e-3;
  if (field.ends_with(".damping") || field.ends_with(".frictionloss")) floor = 0.1;
  else if (field.ends_with(".stiffness")) floor = 1.0;
  else if (field.ends_with(".armature")) floor = 0.01;
  return std::max(std::abs(value), floor);
}

/// The length of body `b`: the larger of its centre's distance from the body's origin and its radius of
/// gyration sqrt((I1 + I2 + I3) / (2 m)) (the rms distance of its mass from the centre). A shift of the
/// centre of mass is measured against it, and stays within it.
double body_length(const mjModel* m, int b) {
  const double* c = m->body_ipos + 3 * b;
  const double* inertia = m->body_inertia + 3 * b;
  const double offset = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  const double gyration =
      m->body_mass[b] > 0.0 ? std::sqrt((inertia[0] + inertia[1] + inertia[2]) / (2.0 * m->body_mass[b])) : 0.0;
  return std::max({offset, gyration, 1e-3});
}

}  // namespace

std::vector<LibraryEffect> mujoco_effect_library(const MujocoSystem& system) {
  using namespace effect_bases;
  const auto& model = system.model();
  const mjModel* m = model->m();
  const int nv = m->nv;
  std::vector<LibraryEffect> out;
  for (const std::string& joint : system.joint_names()) {
    const int dof = system.joint_dof(joint);
    const int id = mj_name2id(m, mjOBJ_JOINT, joint.c_str());
    const bool slide = m->jnt_type[id] == mjJNT_SLIDE;
    out.push_back(linear_force_entry("joint_viscous_damping:" + joint, {"b", slide ? "N s/m" : "N m s/rad", 0.1, 0.0},
                                     fmt::format("Q_{0} = -b {0}_dot", joint), nv, viscous(dof, nv + dof)));
    out.push_back(coulomb_friction_entry("joint_coulomb_friction:" + joint, {"tau", slide ? "N" : "N m", 0.1, 0.0}, joint,
                                         joint + "_dot", nv, dof, nv + dof));
    // A cubic spring where the model gives the joint a spring (stiffness > 0), whose force may stiffen
    // or soften with the displacement (a Duffing oscillator). A joint without a spring has no rest
    // position to be displaced from: a slide's origin is a convention, and a hinge may turn freely (a
    // potential of a free angle is periodic; a cubic is not).
    if (m->jnt_stiffness[id] > 0.0) {
      const int position = m->jnt_qposadr[id];
      const double reference = m->qpos_spring[position];
      const double stiffness = m->jnt_stiffness[id];
      out.push_back(linear_force_entry(
          "joint_cubic_spring:" + joint,
          {"k3", slide ? "N/m^3" : "N m/rad^3", stiffness},
          reference == 0.0 ? fmt::format("Q_{0} = -k3 {0}^3", joint)
                           : fmt::format("Q_{0} = -k3 ({0} - {1:.6g})^3", joint, reference),
          nv, cubic_spring(dof, position, reference)));
    }
  }
  for (const std::string& actuator : system.actuator_names()) {
    LibraryEffect gain = recalibration_entry("actuator_gain:" + actuator, {actuator + ".gain", "-", 1.0}, true, true);
    gain.parameters[0].name = "k";
    gain.formula = fmt::format("actuator {} applies k u", actuator);
    out.push_back(std::move(gain));
  }
  out.push_back(input_delay_entry());
  const char* axes[] = {"x", "y", "z"};
  const auto bodies = system.body_names();
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    if (bodies[b].empty()) continue;
    for (int axis = 0; axis < 3; ++axis) {
      const std::string name = fmt::format("external_force_{}:{}", axes[axis], bodies[b]);
      out.push_back(force_entry(std::make_shared<BodyForceEffect>(
          model, static_cast<int>(b) + 1, axis, name,
          fmt::format("constant world-frame force F e_{} at the centre of mass of {}", axes[axis], bodies[b]))));
    }
  }
  for (const Parameter& p : system.parameters()) {
    if (p.name.ends_with(".gain")) continue;  // actuator_gain:<actuator> above
    const bool non_negative = !p.name.ends_with(".mass");
    LibraryEffect e = recalibration_entry("param:" + p.name, p, non_negative, false);
    e.parameters[0].scale = typical_scale(p.name, p.value);
    if (p.name.ends_with(".gear")) e.parameters[0].lower = -std::numeric_limits<double>::infinity();
    if (const auto at = p.name.rfind(".com_"); at != std::string::npos && p.name.size() == at + 6) {
      // A centre-of-mass coordinate has either sign and may be zero in the file. It moves by at most the
      // body's length: a centre further from the model's is not the same body. (Moved at a fixed inertia
      // about the centre, it also adds m (c'^2 - c^2) to the inertia about the body's origin; unbounded,
      // a centre 0.24 m off a 0.08 m link stood in for a joint's inertia about a vertical axis.)
      const double length = body_length(m, mj_name2id(m, mjOBJ_BODY, p.name.substr(0, at).c_str()));
      e.parameters[0].lower = p.value - length;
      e.parameters[0].upper = p.value + length;
      e.parameters[0].strictly_positive = false;
      e.parameters[0].scale = length;
    }
    if (const auto at = p.name.rfind(".second_moment_"); at != std::string::npos && p.name.size() == at + 16) {
      // A second moment S_k = integral of r_k^2 dm is >= 0 (the moments then satisfy the triangle
      // inequality: a body), and grows by at most m L^2, the body's mass at its length. Its typical
      // size is the mean of the three, (I_1 + I_2 + I_3) / 6; two may be zero (a thin rod's, across it).
      const int body = mj_name2id(m, mjOBJ_BODY, p.name.substr(0, at).c_str());
      const double* moments = m->body_inertia + 3 * body;
      const double length = body_length(m, body);
      e.parameters[0].lower = 0.0;
      e.parameters[0].upper = p.value + m->body_mass[body] * length * length;
      e.parameters[0].strictly_positive = false;
      e.parameters[0].scale = (moments[0] + moments[1] + moments[2]) / 6.0;
      if (!(e.parameters[0].scale > 0.0)) continue;  // a point mass: no spread to recalibrate
      e.on_request = true;
    }
    out.push_back(std::move(e));
  }
  return out;
}

SystemEntry mujoco_system_entry(const std::string& path) {
  const std::shared_ptr<const MujocoSystem> file = MujocoSystem::load(path);
  SystemEntry entry;
  entry.name = path;
  entry.description = fmt::format("MuJoCo model '{}' ({}): {} joints, {} actuators, timestep {} s", file->name(), path,
                                  file->joint_names().size(), file->actuator_names().size(), file->timestep());
  entry.origin = path;
  entry.build = [file](Preset, const std::map<std::string, double>& overrides, const ActuatorNoise& noise) -> DynamicsPtr {
    // A model file has one parameter set, the file's: both presets build it, and the "real world"
    // differs by overrides or by another file (docs/own-system.md#1-the-model-file).
    auto system = overrides.empty() ? std::make_shared<MujocoSystem>(file->model()) : file->with_parameters(overrides);
    system->set_noise_model(noise);
    return system;
  };
  entry.effects = mujoco_effect_library(*file);
  complete_system_entry(entry);
  // A joint's damping is viscous friction, its frictionloss dry (Coulomb) friction: the library's forces
  // of the same physics, never both in one set.
  for (const std::string& joint : file->joint_names()) {
    entry.same_physics.push_back({"param:" + joint + ".damping", "joint_viscous_damping:" + joint});
    entry.same_physics.push_back({"param:" + joint + ".frictionloss", "joint_coulomb_friction:" + joint});
  }
  for (const std::string& actuator : file->actuator_names())
    entry.same_physics.push_back({"param:" + actuator + ".gear", "actuator_gain:" + actuator});
  return entry;
}

}  // namespace gpilqg
