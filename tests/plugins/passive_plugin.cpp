// A plugin whose system has no controls (m = 0): a damped pendulum, theta_ddot = -(g / l) sin theta
// - b theta_dot / (m l^2) + Q_theta / (m l^2), with m = 1 kg, l = 0.5 m, b = 0 (sim) or 0.2 N m s/rad
// (real). Its entry lists actuator_gain and input_delay as a careless author might; the registry drops
// them (no controls). For the command line's tests of passive plugin systems.
#include <cmath>
#include <stdexcept>

#include "gpilqg/core/effect_builders.hpp"
#include "gpilqg/core/generalised_forces.hpp"
#include "gpilqg/core/plugin.hpp"

namespace {

class PassivePendulum final : public gpilqg::Dynamics, public gpilqg::GeneralisedForceInput {
 public:
  explicit PassivePendulum(double damping) : damping_(damping) {}
  const std::string& name() const override { return name_; }
  const std::vector<gpilqg::Quantity>& states() const override { return states_; }
  const std::vector<gpilqg::Quantity>& controls() const override { return controls_; }
  std::vector<gpilqg::Parameter> parameters() const override { return {{"damping", "N m s/rad", damping_}}; }
  void evaluate(const gpilqg::VectorCRef& x, const gpilqg::VectorCRef&, gpilqg::VectorRef xdot,
                gpilqg::DynamicsJacobians* jacobians) const override {
    xdot(0) = x(1);
    xdot(1) = -(kG / kL) * std::sin(x(0)) - damping_ * x(1) / kI;
    if (jacobians == nullptr) return;
    jacobians->resize(2, 0);
    jacobians->fx << 0.0, 1.0, -(kG / kL) * std::cos(x(0)), -damping_ / kI;
  }
  const std::vector<gpilqg::Quantity>& generalised_forces() const override { return forces_; }
  void generalised_force_map(const gpilqg::VectorCRef&, gpilqg::Matrix& W,
                             std::vector<gpilqg::Matrix>* d_dx) const override {
    W.setZero(2, 1);
    W(1, 0) = 1.0 / kI;
    if (d_dx != nullptr) d_dx->assign(2, gpilqg::Matrix::Zero(2, 1));
  }

 private:
  static constexpr double kG = 9.81, kL = 0.5, kI = 0.25;  // m l^2 with m = 1 kg
  double damping_;
  std::string name_ = "passive_pendulum";
  std::vector<gpilqg::Quantity> states_ = {{"theta", "rad"}, {"theta_dot", "rad/s"}};
  std::vector<gpilqg::Quantity> controls_;
  std::vector<gpilqg::Quantity> forces_ = {{"Q_theta", "N m"}};
};

}  // namespace

GPILQG_PLUGIN(registrar) {
  using namespace gpilqg::effect_bases;
  gpilqg::SystemEntry entry;
  entry.name = "passive_pendulum";
  entry.description = "a damped pendulum without controls (sim: no damping, real: 0.2 N m s/rad)";
  entry.build = [](gpilqg::Preset preset, const std::map<std::string, double>& overrides,
                   const gpilqg::ActuatorNoise& noise) {
    double damping = preset == gpilqg::Preset::Simulator ? 0.0 : 0.2;
    for (const auto& [name, value] : overrides) {
      if (name != "damping")
        throw std::invalid_argument("unknown parameter '" + name + "' for system 'passive_pendulum'; expected damping");
      damping = value;
    }
    auto system = std::make_shared<PassivePendulum>(damping);
    system->set_noise_model(noise);
    return gpilqg::DynamicsPtr(system);
  };
  entry.effects.push_back(gpilqg::linear_force_entry("joint_viscous_damping:theta", {"b", "N m s/rad", 0.1},
                                                     "Q_theta = -b theta_dot", 1, viscous(0, 1)));
  entry.effects.push_back(gpilqg::actuator_gain_entry());
  entry.effects.push_back(gpilqg::input_delay_entry());
  registrar.add(entry);
}
