#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"

#include <stdexcept>

#include <Eigen/QR>
#include <fmt/format.h>

#include "gpilqg/core/effects.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"

namespace gpilqg::diagnosis {

const Dynamics* force_map_owner(const Dynamics& model) {
  const Dynamics* system = &model;
  while (dynamic_cast<const GeneralisedForceInput*>(system) == nullptr) {
    const auto* decorated = dynamic_cast<const EffectDynamics*>(system);
    if (decorated == nullptr) return nullptr;
    system = &decorated->base();
  }
  return system;
}

const Dynamics& force_map_system(const Dynamics& model) {
  const Dynamics* owner = force_map_owner(model);
  if (owner == nullptr)
    throw std::invalid_argument(fmt::format(
        "inverse-dynamics residual: system '{}' has no generalised-force map (its equations do not accept extra "
        "generalised forces), so it has no force residual", model.name()));
  return *owner;
}

std::vector<int> ForceComponents::velocity_states() const {
  std::vector<int> out;
  out.reserve(coordinates.size());
  for (const GeneralisedCoordinate& c : coordinates) out.push_back(c.velocity);
  return out;
}

ForceComponents force_components(const Dynamics& model) {
  const Dynamics& owner = force_map_system(model);
  ForceComponents out;
  out.forces = dynamic_cast<const GeneralisedForceInput&>(owner).generalised_forces();
  const std::vector<GeneralisedCoordinate> coordinates = generalised_coordinates(owner);
  out.coordinates.resize(out.forces.size());
  std::vector<bool> found(out.forces.size(), false);
  for (const GeneralisedCoordinate& c : coordinates) {
    out.coordinates[static_cast<std::size_t>(c.component)] = c;
    found[static_cast<std::size_t>(c.component)] = true;
  }
  for (std::size_t i = 0; i < found.size(); ++i)
    if (!found[i])
      throw std::invalid_argument(fmt::format(
          "inverse-dynamics residual: force component '{}' of system '{}' acts on no coordinate with a velocity "
          "state, so its acceleration cannot be measured", out.forces[i].name, model.name()));
  return out;
}

GeneralisedForceParts generalised_force_parts(const Dynamics& model, const Transitions& data, const Matrix& applied_u,
                                              const Matrix& accelerations, const std::vector<int>& rows) {
  const Dynamics& owner = force_map_system(model);
  const auto& map = dynamic_cast<const GeneralisedForceInput&>(owner);
  const ForceComponents components = force_components(model);
  const auto k = static_cast<Eigen::Index>(components.forces.size());
  const int n = model.state_dim();
  if (data.x.cols() != n)
    throw DataProblem(fmt::format("inverse-dynamics residual: the data have {} states; system '{}' has {}",
                                            data.x.cols(), model.name(), n));
  if (applied_u.rows() != data.size() || applied_u.cols() != model.control_dim())
    throw std::invalid_argument(fmt::format(
        "inverse-dynamics residual: the applied controls are {} x {}; expected {} x {} (one row per transition)",
        applied_u.rows(), applied_u.cols(), data.size(), model.control_dim()));
  if (accelerations.rows() != data.size() || accelerations.cols() != k)
    throw std::invalid_argument(fmt::format(
        "inverse-dynamics residual: the accelerations are {} x {}; expected {} x {} (one row per transition, one "
        "column per force component)", accelerations.rows(), accelerations.cols(), data.size(), k));
  const std::vector<int> velocity = components.velocity_states();

  const auto model_workspace = model.make_workspace();
  const auto map_workspace = owner.make_workspace();
  // The direct form where the owner has one (GeneralisedForceInput::inverse_dynamics_parts): `model`
  // is the owner, or effects over it, which apply k u to it and add their forces Q_e.
  const auto* decorated = dynamic_cast<const EffectDynamics*>(&model);
  const bool direct = &owner == &model || (decorated != nullptr && &decorated->base() == &owner);
  const double gain = decorated != nullptr ? decorated->actuator_gain() : 1.0;
  const bool effects = decorated != nullptr && !decorated->effects().empty();
  Vector qdd(k), inertial(k), forces(k), Q_e(k);
  Vector x(n);
  Vector u(model.control_dim());
  Vector xdot(n);
  Matrix W(n, k);
  Matrix W_v(k, k);
  Vector f_v(k);
  Eigen::ColPivHouseholderQR<Matrix> factor(k, k);
  GeneralisedForceParts out{Matrix(static_cast<Eigen::Index>(rows.size()), k),
                            Matrix(static_cast<Eigen::Index>(rows.size()), k)};
  const auto not_finite = [&](int t, const std::string& what) {
    return DataProblem(fmt::format("inverse-dynamics residual: at row {} (episode {}, t = {}) the model's {}; "
                                             "no force residual there",
                                             t, data.episode[static_cast<std::size_t>(t)],
                                             data.t.size() > t ? data.t(t) : 0.0, what));
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int t = rows[i];
    if (t < 0 || t >= data.size())
      throw std::invalid_argument(
          fmt::format("inverse-dynamics residual: row {}; the data have {} transitions", t, data.size()));
    x = data.x.row(t).transpose();
    u = applied_u.row(t).transpose();
    qdd = accelerations.row(t).transpose();
    if (!(direct && map.inverse_dynamics_parts(x, gain * u, qdd, inertial, forces, *map_workspace))) {
      model.evaluate(x, u, xdot, nullptr, *model_workspace);
      map.generalised_force_map(x, W, nullptr, *map_workspace);
      for (Eigen::Index c = 0; c < k; ++c) {
        const int v = velocity[static_cast<std::size_t>(c)];
        W_v.row(c) = W.row(v);
        f_v(c) = xdot(v);
      }
      factor.compute(W_v);
      if (factor.rank() < k) throw not_finite(t, "generalised-force map is singular");
      inertial = factor.solve(qdd);
      forces = -factor.solve(f_v);
    } else if (effects) {
      decorated->generalised_force(x, u, Q_e, *model_workspace);
      forces -= Q_e;
    }
    if (!inertial.allFinite() || !forces.allFinite()) throw not_finite(t, "acceleration or the measured one is not finite");
    out.inertial.row(static_cast<Eigen::Index>(i)) = inertial.transpose();
    out.forces.row(static_cast<Eigen::Index>(i)) = forces.transpose();
  }
  return out;
}

Matrix generalised_force_residual(const Dynamics& model, const Transitions& data, const Matrix& applied_u,
                                  const Matrix& accelerations, const std::vector<int>& rows) {
  GeneralisedForceParts parts = generalised_force_parts(model, data, applied_u, accelerations, rows);
  parts.inertial += parts.forces;
  return parts.inertial;
}

Matrix generalised_force_residual(const ModelSpec& model, const Transitions& data, const Matrix& accelerations,
                                  const std::vector<int>& rows) {
  return generalised_force_residual(model, data, applied_controls(data, model.input_delay), accelerations, rows);
}

Matrix generalised_force_residual(const ModelSpec& model, const Transitions& data, const Matrix& controls,
                                  const Matrix& accelerations, const std::vector<int>& rows) {
  const DynamicsPtr system = model.build();
  return generalised_force_residual(*system, data, controls, accelerations, rows);
}

}  // namespace gpilqg::diagnosis
