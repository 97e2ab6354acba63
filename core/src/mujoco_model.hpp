#pragma once
/// The loaded mjModel behind a MujocoSystem: validated once, immutable afterwards, with its names and
/// its parameter fields; and the workspace that holds a caller's mjData (mujoco_system.hpp).

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

class MujocoModel {
 public:
  /// Loads and validates the file (see MujocoSystem::load for the errors).
  static std::shared_ptr<const MujocoModel> load(const std::string& path);

  /// A copy with parameter fields set by name; throws std::invalid_argument listing the names for
  /// an unknown one and for a value outside the field's range.
  std::shared_ptr<const MujocoModel> with_parameters(const std::map<std::string, double>& overrides) const;

  ~MujocoModel();
  MujocoModel(const MujocoModel&) = delete;
  MujocoModel& operator=(const MujocoModel&) = delete;

  const mjModel* m() const { return m_; }
  const std::string& path() const { return path_; }
  const std::string& name() const { return name_; }
  int nq() const { return m_->nq; }
  int nu() const { return m_->nu; }

  const std::vector<Quantity>& states() const { return states_; }
  const std::vector<Quantity>& controls() const { return controls_; }
  const std::vector<Quantity>& forces() const { return forces_; }
  std::vector<Parameter> parameters() const;
  /// The actuator gains k (nu): the applied control is k .* u.
  const Vector& gains() const { return gains_; }

  std::vector<std::string> body_names() const;    ///< without the world body
  std::vector<std::string> joint_names() const;
  std::vector<std::string> actuator_names() const;

  struct DataDeleter {
    void operator()(mjData* d) const { mj_deleteData(d); }
  };
  using DataPtr = std::unique_ptr<mjData, DataDeleter>;
  /// A new mjData for this model (or any copy with other parameter values: the sizes are the same).
  DataPtr make_data() const;
  /// Puts `d` in the state (qpos, qvel) = x with ctrl = k .* u, no applied forces, zero time and warm
  /// start, no passive-force context and no warnings, so that results never depend on the history of d.
  void prepare(mjData* d, const VectorCRef& x, const VectorCRef& u) const;

  /// The index of the userdata slot that holds the passive-force context (mujoco_system.cpp).
  int context_slot() const { return m_->nuserdata - 1; }

 private:
  explicit MujocoModel(mjModel* m, std::string path);
  void read_names();
  void read_second_moments();  ///< second_moments_ from body_inertia

  struct Field {
    std::string name;
    std::string unit;
    double* value;   ///< in m_ (a second moment: in second_moments_, written back by with_parameters)
    double lower;    ///< physical range
    bool positive;   ///< strictly above lower
  };
  /// The named parameter fields, pointing into m_ (which only with_parameters' fresh copy writes).
  std::vector<Field> fields() const;

  mjModel* m_;
  std::string path_;
  std::string name_;
  std::vector<Quantity> states_, controls_, forces_;
  Vector gains_;
  /// Each body's principal second moments of mass about its centre, S_k = integral of r_k^2 dm along
  /// the axes of its inertial frame (3 per body, from body_inertia: S_1 = (I_2 + I_3 - I_1) / 2, ...).
  Vector second_moments_;
};

/// A MujocoSystem's workspace: the caller's own mjData.
struct MujocoWorkspace final : DynamicsWorkspace {
  MujocoModel::DataPtr data;
  Vector scratch;  ///< nv entries for MujocoSystem::inverse_dynamics_parts
};

}  // namespace gpilqg
