#include "mujoco_actuator_units.hpp"

namespace gpilqg {

namespace {

/// What the actuator's control is, judged from its gain, bias and dynamics alone.
enum class ControlKind { Force, Position, Velocity, Unknown };

ControlKind control_kind(const mjModel* m, int a) {
  if (m->actuator_dyntype[a] != mjDYN_NONE || m->actuator_gaintype[a] != mjGAIN_FIXED) return ControlKind::Unknown;
  const mjtNum gain = m->actuator_gainprm[a * mjNGAIN];
  const mjtNum* bias = m->actuator_biasprm + a * mjNBIAS;
  // <motor>, or a <general> left at its defaults: the actuator force is the control itself.
  if (m->actuator_biastype[a] == mjBIAS_NONE) return gain == 1.0 ? ControlKind::Force : ControlKind::Unknown;
  if (m->actuator_biastype[a] != mjBIAS_AFFINE || gain == 0.0 || bias[0] != 0.0) return ControlKind::Unknown;
  // force = kp (ctrl - length) - kv velocity: the control is the length set point.
  if (bias[1] == -gain && bias[2] <= 0.0) return ControlKind::Position;
  // force = kv (ctrl - velocity): the control is the velocity set point.
  if (bias[1] == 0.0 && bias[2] == -gain) return ControlKind::Velocity;
  return ControlKind::Unknown;
}

}  // namespace

std::string actuator_control_unit(const mjModel* m, int actuator) {
  const int transmission = m->actuator_trntype[actuator];
  if (transmission != mjTRN_JOINT && transmission != mjTRN_JOINTINPARENT) return "-";
  const int joint = m->actuator_trnid[2 * actuator];
  const int type = m->jnt_type[joint];
  if (type != mjJNT_HINGE && type != mjJNT_SLIDE) return "-";
  const bool slide = type == mjJNT_SLIDE;
  switch (control_kind(m, actuator)) {
    case ControlKind::Force: return slide ? "N" : "N m";
    case ControlKind::Position: return slide ? "m" : "rad";
    case ControlKind::Velocity: return slide ? "m/s" : "rad/s";
    case ControlKind::Unknown: break;
  }
  return "-";
}

}  // namespace gpilqg
