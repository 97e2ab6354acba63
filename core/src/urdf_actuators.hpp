#pragma once
/// The motors gpilqg gives a URDF robot (MuJoCo imports no actuators from a URDF): one motor per
/// revolute, continuous or prismatic joint, named "<joint>_motor", with the joint's effort limit
/// (<limit effort="E">) as its control range [-E, E] (N m or N, gear 1):
///   - effort > 0: a motor bounded by +-E;
///   - no effort (a continuous joint without <limit>, or <limit> without effort): a motor without bound;
///   - effort = 0: no motor, the joint is passive (all zero: a passive robot, no controls).
/// A negative or non-numeric effort is an error naming the file and the joint.

#include <optional>
#include <string>
#include <vector>

namespace gpilqg::urdf {

struct Joint {
  std::string name;
  std::string type;               ///< "revolute", "continuous", "prismatic", "fixed", ...
  std::optional<double> effort;   ///< <limit effort="...">, when given
};

/// Whether the XML text's root element is <robot> (a URDF; MJCF's is <mujoco>).
bool is_urdf(const std::string& text);

/// The joints of a URDF in file order. Throws std::invalid_argument naming `path` (and the joint) for
/// malformed XML or a bad effort.
std::vector<Joint> read_joints(const std::string& text, const std::string& path);

/// The <actuator> section of the motors of `joints` in the order of `model_joints` (MuJoCo's joint
/// order); joints not in the URDF list (none normally) get no motor.
std::string actuator_section(const std::vector<Joint>& joints, const std::vector<std::string>& model_joints,
                             const std::string& path);

}  // namespace gpilqg::urdf
