#pragma once
/// @file mujoco_system.hpp
/// A MuJoCo model (MJCF, or URDF as MuJoCo loads it) as a gpilqg system
/// (docs/formats.md#systems-and-their-names; docs/own-system.md).
///
/// States: the joint positions in model order, named by joint name, then their velocities named
/// `<joint>_dot`. Controls: the actuators in model order, named by actuator name; a model without
/// actuators is a passive system (no controls, m = 0). A URDF's revolute, continuous and prismatic
/// joints get one motor each, "<joint>_motor" with gear 1, bounded by the joint's <limit effort> (effort
/// 0: no motor; no effort: unbounded). Hinge and slide joints only (then nq = nv and x = [qpos; qvel]);
/// actuators without activation states (na = 0).
///
/// Continuous time (Dynamics): xdot = [qvel; qacc(qpos, qvel, k .* u)] from mj_forward, with the
/// generalised-force map W = [0; M(q)^-1] (nv forces, one per degree of freedom), so the
/// physical-effects library applies to every model. Jacobians of f are central differences.
///
/// Discrete time (OwnIntegrator): the simulator is the model's own integrator and timestep. A step
/// of length dt = s * timestep is s calls of mj_step; A and B come from MuJoCo's finite differences
/// (mjd_transitionFD, centred) chained over the s sub-steps:
///
///   A = A_s ... A_1,   B = sum_i A_s ... A_{i+1} B_i diag(k),
///
/// where k are the actuator gains ("<actuator>.gain", the applied control is k u). Force effects
/// (EffectDynamics) enter inside every sub-step as passive forces, through MuJoCo's passive-force
/// callback, so mj_step and mjd_transitionFD both see them, with their dependence on the state.
///
/// Parameters by name, each a field of the model (docs/own-system.md#1-the-model-file):
///   "<body>.mass" (kg; the body's inertia scales with it), "<joint>.damping", "<joint>.armature",
///   "<joint>.frictionloss", "<joint>.stiffness" (the model's units), "<actuator>.gear" (-),
///   "<actuator>.gain" (-, 1 in the file: the applied control is gain * u).
///
/// Thread safety: a MujocoSystem and its step model are immutable; the mjData each call works in
/// belongs to the caller's workspace (make_workspace()), and every call sets the whole state first, so
/// results never depend on the workspace's history and any number of threads can step one model.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/generalised_forces.hpp"
#include "gpilqg/core/step_model.hpp"
#include "gpilqg/core/system_registry.hpp"

namespace gpilqg {

class MujocoModel;  // the loaded mjModel with its names and fields (mujoco_model.hpp, internal)

class MujocoSystem final : public Dynamics, public GeneralisedForceInput, public OwnIntegrator {
 public:
  /// Loads `path` and applies `overrides` by parameter name. Throws std::invalid_argument with the
  /// file (and MuJoCo's line) for a model MuJoCo rejects, naming the joint for a free or ball joint,
  /// the index for an unnamed joint or actuator, the joint for a URDF's bad effort limit, and listing
  /// the valid names for an unknown parameter.
  static std::shared_ptr<MujocoSystem> load(const std::string& path, const std::map<std::string, double>& overrides = {});

  /// The same model with other parameter values (overrides apply on top of this system's values).
  std::shared_ptr<MujocoSystem> with_parameters(const std::map<std::string, double>& overrides) const;

  const std::string& name() const override;
  const std::vector<Quantity>& states() const override;
  const std::vector<Quantity>& controls() const override;
  std::vector<Parameter> parameters() const override;

  /// Holds the caller's own mjData.
  std::unique_ptr<DynamicsWorkspace> make_workspace() const override;
  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                DynamicsJacobians* jacobians = nullptr) const override;
  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot, DynamicsJacobians* jacobians,
                DynamicsWorkspace& workspace) const override;

  /// b = df/du by central differences of fu, in the caller's mjData.
  void input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out,
                    DynamicsWorkspace& workspace) const override {
    input_matrix_by_differences(x, u, out, &workspace);
  }

  const std::vector<Quantity>& generalised_forces() const override;
  /// W = [0; M(q)^-1] (n x nv); dW/dx_j by central differences over q_j (zero for velocities).
  void generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const override;
  void generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx,
                             DynamicsWorkspace& workspace) const override;
  /// W_v^-1 (qdd - f_v) = M(q) (qdd - qacc) with W = [0; M^-1], in its two terms; always true. Without
  /// constraint rows at x (frictionloss, an active limit or contact) f_v = M^-1 (Q_passive +
  /// Q_actuator - c), so the terms are M qdd (one product with M, mj_mulM) and c - Q_passive -
  /// Q_actuator from MuJoCo's position, velocity and actuation stages: no factorisation and no forward
  /// solve. With constraint rows their forces come from the forward solver: the rest of the forward
  /// pass, then -M qacc.
  bool inverse_dynamics_parts(const VectorCRef& x, const VectorCRef& u, const VectorCRef& qdd, VectorRef inertial,
                              VectorRef forces, DynamicsWorkspace& workspace) const override;
  /// MuJoCo's actuator forces in joint space (qfrc_actuator) from the position, velocity and
  /// actuation stages: no constraint solve.
  bool control_forces(const VectorCRef& x, const VectorCRef& u, VectorRef Q, DynamicsWorkspace& workspace) const override;

  /// The model's integrator and timestep with `decorated`'s effects (this system, or an EffectDynamics
  /// over it). Throws std::invalid_argument when dt is not a whole multiple of the timestep.
  std::shared_ptr<const StepModel> own_step_model(DynamicsPtr decorated, double dt) const override;
  /// dt not finite and > 0, or not a whole multiple of the timestep (within 1e-6 relative).
  std::optional<std::string> step_problem(double dt) const override;

  /// The model's timestep [s].
  double timestep() const;
  /// The file the model was loaded from.
  const std::string& path() const;
  /// Body, joint and actuator names, in model order (bodies without the world body).
  std::vector<std::string> body_names() const;
  std::vector<std::string> joint_names() const;
  std::vector<std::string> actuator_names() const;
  /// The actuators' control ranges [lower, upper] in units of u (ctrlrange over the gain; infinite
  /// for actuators without ctrllimited).
  std::pair<Vector, Vector> control_limits() const;
  /// Degree of freedom of a joint, or -1 for an unknown name.
  int joint_dof(const std::string& joint) const;

  /// The loaded model (internal: mujoco_model.hpp).
  const std::shared_ptr<const MujocoModel>& model() const { return model_; }

  explicit MujocoSystem(std::shared_ptr<const MujocoModel> model);

 private:
  std::shared_ptr<const MujocoModel> model_;
};

/// The registry entry of a model file (system_registry.hpp calls this for names ending in .xml or
/// .urdf): builder (both presets are the file's values; `overrides` set fields), the generic effect
/// library of docs/own-system.md#3-diagnosis-what-is-the-model-missing, no default run config. Throws
/// like MujocoSystem::load.
SystemEntry mujoco_system_entry(const std::string& path);

/// The generic effects of a system with a generalised-force map whose generalised forces are one per
/// degree of freedom named after its joints (MuJoCo models): joint_viscous_damping:<joint>,
/// joint_coulomb_friction:<joint>, actuator_gain:<actuator>, external_force_{x,y,z}:<body>, then
/// param:<field> for every parameter except the gains.
std::vector<LibraryEffect> mujoco_effect_library(const MujocoSystem& system);

/// A file a MuJoCo model reads besides itself: an MJCF file it includes (`<include file>`, also nested),
/// or an asset that exists (a mesh, skin, height-field or texture file; a URDF's `<mesh filename>`), found
/// the way MuJoCo 2.2 finds it. `what` says which, e.g. "an included MJCF file", "a mesh file".
struct ModelDependency {
  std::filesystem::path file;
  std::string what;
};

/// The files the model at `path` reads besides itself, in document order (each once): part of what a
/// run depends on. Throws std::invalid_argument naming a file that cannot be read.
std::vector<ModelDependency> mujoco_model_dependencies(const std::string& path);

}  // namespace gpilqg
