#include "gpilqg/control/trajectory.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg {

Trajectory::Trajectory(int state_dim, int control_dim, int horizon)
    : x(Matrix::Zero(state_dim, horizon + 1)), u(Matrix::Zero(control_dim, horizon)) {
  if (state_dim < 1 || control_dim < 0 || horizon < 0)
    throw std::invalid_argument("Trajectory(" + std::to_string(state_dim) + ", " +
                                std::to_string(control_dim) + ", " + std::to_string(horizon) +
                                "): expected n >= 1, m >= 0, T >= 0");
}

}  // namespace gpilqg
