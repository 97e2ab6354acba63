#pragma once
/// The motors gpilqg gives a URDF robot (MuJoCo imports no actuators from a URDF): one motor per
/// revolute, continuous or prismatic joint, named "<joint>_motor", with the joint's effort limit
/// (<limit effort="E">) as its control range [-E, E] (N m or N, gear 1):
///   - effort > 0: a motor bounded by +-E;
///   - no effort (a continuous joint without <limit>, or <limit> without effort): a motor without bound;
///   - effort = 0: no motor, the joint is passive (all zero: a passive robot, no controls).
/// A negative or non-numeric effort is an error naming the file and the joint.
///
/// The joint types are URDF's, spelled in lower case: revolute, continuous, prismatic, fixed and
/// floating (which the MuJoCo system then refuses as a free joint); any other type, a planar joint
/// included (MuJoCo would split it into three joints without motors), is an error naming the file, the
/// line, the joint and the types allowed. A joint with <mimic joint="j" multiplier="a" offset="b"/>
/// follows joint j, q = a q_j + b: it gets no motor, and the model holds it there by a MuJoCo joint
/// equality (equality_section), as it holds any other MJCF equality constraint.
///
/// Every number MuJoCo reads from the file (an origin, an axis, a mass, an inertia, limits, damping and
/// friction, a geometry's size) must be finite and have its count of values, a joint's damping and
/// friction >= 0, and a limit's lower <= upper: MuJoCo takes a NaN with a warning and drops some of
/// them (a NaN rpy becomes no rotation, limits with lower > upper become no limits), so each is an
/// error naming the file, the line and the attribute.

#include <optional>
#include <string>
#include <vector>

namespace gpilqg::urdf {

/// <mimic joint="..." multiplier="..." offset="..."/>: q = multiplier q_joint + offset.
struct Mimic {
  std::string joint;
  double multiplier = 1.0;
  double offset = 0.0;
};

struct Joint {
  std::string name;
  std::string type;               ///< "revolute", "continuous", "prismatic", "fixed" or "floating"
  long line = 0;                  ///< of its <joint> tag in the file
  std::optional<double> effort;   ///< <limit effort="...">, when given
  std::optional<Mimic> mimic;     ///< <mimic>, when given
};

/// Whether the XML text's root element is <robot> (a URDF; MJCF's is <mujoco>).
bool is_urdf(const std::string& text);

/// The joints of a URDF in file order. Throws std::invalid_argument naming `path` (and the line and
/// joint) for malformed XML, a number that breaks the rules above, a joint type outside the list above,
/// a bad effort, or a <mimic> without a finite multiplier and offset or whose joint is not another
/// moving joint of the file.
std::vector<Joint> read_joints(const std::string& text, const std::string& path);

/// The <actuator> section of the motors of `joints` in the order of `model_joints` (MuJoCo's joint
/// order); joints not in the URDF list (none normally) get no motor.
std::string actuator_section(const std::vector<Joint>& joints, const std::vector<std::string>& model_joints,
                             const std::string& path);

/// The <equality> section that holds every mimicking joint of `joints` at its leader: one
/// <joint joint1="follower" joint2="leader" polycoef="offset multiplier 0 0 0"/> each (MuJoCo's
/// q_1 - q_1,ref = sum c_k (q_2 - q_2,ref)^k, the references 0 in a URDF); "" when none mimics.
std::string equality_section(const std::vector<Joint>& joints);

}  // namespace gpilqg::urdf
