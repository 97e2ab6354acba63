#pragma once
/// @file mujoco_actuator_units.hpp
/// The unit of a MuJoCo actuator's control, read off its transmission and its gain and bias, so that
/// data files, `gpilqg data info` and the import report show what a human reads off the model:
///
/// | actuator (as MuJoCo compiles it)                         | on a hinge | on a slide |
/// |----------------------------------------------------------|------------|------------|
/// | motor: fixed gain 1, no bias (force = ctrl)              | N m        | N          |
/// | position servo: fixed gain kp, bias (0, -kp, -kv <= 0)   | rad        | m          |
/// | velocity servo: fixed gain kv, bias (0, 0, -kv)          | rad/s      | m/s        |
///
/// The gear of a joint transmission is dimensionless (the actuator's length is gear * q, its force
/// enters the joint as gear * force), so any gear keeps these units. Every other actuator (a tendon,
/// site, slider-crank or body transmission; a general actuator with a gain other than 1, a bias of
/// its own, or activation dynamics) has no unit that can be derived from the model, and gets "-".

#include <mujoco/mujoco.h>

#include <string>

namespace gpilqg {

/// The unit of actuator `actuator`'s control (the table above), or "-" when it cannot be derived.
std::string actuator_control_unit(const mjModel* m, int actuator);

}  // namespace gpilqg
