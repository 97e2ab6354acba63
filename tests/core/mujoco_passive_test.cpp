// Systems without controls (m = 0, passive systems) and URDF robots (mujoco_system.hpp): a MuJoCo
// model without actuators loads as a passive system and steps; a URDF's revolute, continuous and
// prismatic joints get one motor each bounded by the joint's effort limit (effort 0: no motor); bad
// efforts are errors naming the file and the joint; joint types outside URDF's list are refused; a
// <mimic> joint follows its leader; the file's numbers reach the model to the last digit, and numbers
// MuJoCo would take with a warning or drop are refused (URDF and MJCF); measurement files without
// control columns.

#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <H5Cpp.h>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/mujoco_system.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

std::string pendulum_path() { return (test::source_dir() / "data" / "pendulum_passive.xml").string(); }
std::string urdf_arm_path() { return (test::source_dir() / "data" / "two_link_arm.urdf").string(); }

std::vector<std::string> effect_names_of(const std::string& system) {
  std::vector<std::string> out;
  for (const LibraryEffect& e : find_system(system)->effects) out.push_back(e.name);
  return out;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

TEST(PassiveSystem, AModelWithoutActuatorsLoadsAndSwings) {
  const auto pendulum = MujocoSystem::load(pendulum_path());
  EXPECT_EQ(pendulum->name(), "pendulum_passive");
  EXPECT_EQ(pendulum->control_dim(), 0);
  EXPECT_EQ(names_of(pendulum->states()), (std::vector<std::string>{"swing", "swing_dot"}));
  const Vector x = (Vector(2) << 0.5, 0.0).finished();
  const Vector u(0);
  Vector xdot(2);
  DynamicsJacobians J;
  pendulum->evaluate(x, u, xdot, &J);
  EXPECT_NEAR(xdot(1), -9.81 * std::sin(0.5) * 0.5 / (0.25 + 0.001), 1e-6);  // m g l sin / (m l^2 + I)
  EXPECT_EQ(J.fu.rows(), 2);
  EXPECT_EQ(J.fu.cols(), 0);
  const auto step = pendulum->own_step_model(pendulum, 0.02);
  Vector next(2);
  StepJacobians SJ;
  step->step(x, u, next, &SJ);
  EXPECT_LT(next(1), 0.0);  // it swings back
  EXPECT_EQ(SJ.B.cols(), 0);
  const auto [lower, upper] = pendulum->control_limits();
  EXPECT_EQ(lower.size(), 0);
}

TEST(PassiveSystem, NoEffectOfTheInputIsACandidate) {
  const std::vector<std::string> names = effect_names_of(pendulum_path());
  EXPECT_TRUE(contains(names, "joint_viscous_damping:swing"));
  EXPECT_TRUE(contains(names, "param:swing.damping"));
  EXPECT_FALSE(contains(names, "input_delay"));
  for (const std::string& name : names) EXPECT_EQ(name.rfind("actuator_gain", 0), std::string::npos) << name;
}

TEST(UrdfRobot, EachJointGetsAMotorBoundedByItsEffortLimit) {
  const auto arm = MujocoSystem::load(urdf_arm_path());
  EXPECT_EQ(arm->name(), "two_link_arm_urdf");
  EXPECT_EQ(names_of(arm->states()), (std::vector<std::string>{"shoulder", "elbow", "shoulder_dot", "elbow_dot"}));
  EXPECT_EQ(names_of(arm->controls()), (std::vector<std::string>{"shoulder_motor", "elbow_motor"}));
  for (const Quantity& motor : arm->controls()) EXPECT_EQ(motor.unit, "N m") << motor.name;  // torques on hinges
  const auto [lower, upper] = arm->control_limits();
  EXPECT_MATRIX_NEAR(lower, (Vector(2) << -8.0, -3.0).finished(), 0.0);
  EXPECT_MATRIX_NEAR(upper, (Vector(2) << 8.0, 3.0).finished(), 0.0);
  // The motor applies u as the joint torque (gear 1): at rest, hanging, u = (1, 0) accelerates the shoulder.
  Vector xdot(4);
  arm->evaluate(Vector::Zero(4), (Vector(2) << 1.0, 0.0).finished(), xdot, nullptr);
  EXPECT_GT(xdot(2), 0.0);
  // The URDF's joint damping came along.
  for (const Parameter& p : arm->parameters()) {
    if (p.name == "elbow.damping") {
      EXPECT_DOUBLE_EQ(p.value, 0.05);
    }
  }
}

/// A URDF of a slider and a wheel with the given <limit> elements ("" for none).
fs::path write_urdf(const fs::path& dir, const std::string& slider_limit, const std::string& wheel_limit) {
  const fs::path file = dir / "robot.urdf";
  std::ofstream(file) << R"(<?xml version="1.0"?>
<robot name="slider_wheel">
  <link name="base"/>
  <link name="cart"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="wheel"><inertial><mass value="0.2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <!-- a comment with <joint name="fake" type="revolute"> inside -->
  <joint name="slide" type="prismatic"><parent link="base"/><child link="cart"/><axis xyz="1 0 0"/>)"
                      << slider_limit << R"(</joint>
  <joint name="spin" type="continuous"><parent link="cart"/><child link="wheel"/><axis xyz="0 1 0"/>)"
                      << wheel_limit << R"(</joint>
</robot>
)";
  return file;
}

TEST(UrdfRobot, EffortZeroLeavesAJointPassiveAndNoEffortLeavesTheMotorUnbounded) {
  const fs::path dir = test::temporary_dir("urdf_effort");
  const auto one = MujocoSystem::load(
      write_urdf(dir, R"(<limit lower="-1" upper="1" effort="0" velocity="1"/>)", "").string());
  EXPECT_EQ(names_of(one->controls()), (std::vector<std::string>{"spin_motor"}));
  EXPECT_EQ(one->controls()[0].unit, "N m");  // the wheel's continuous joint: a torque
  const auto both = MujocoSystem::load(write_urdf(dir, R"(<limit lower="-1" upper="1" effort="5" velocity="1"/>)", "").string());
  EXPECT_EQ(names_of(both->controls()), (std::vector<std::string>{"slide_motor", "spin_motor"}));
  EXPECT_EQ(both->controls()[0].unit, "N");  // the prismatic joint: a force
  const auto [lower, upper] = one->control_limits();
  EXPECT_TRUE(std::isinf(lower(0)) && std::isinf(upper(0)));

  const auto passive = MujocoSystem::load(write_urdf(dir, R"(<limit lower="-1" upper="1" effort="0" velocity="1"/>)",
                                                     R"(<limit effort="0.0" velocity="1"/>)")
                                              .string());
  EXPECT_EQ(passive->control_dim(), 0);
  EXPECT_EQ(names_of(passive->states()), (std::vector<std::string>{"slide", "spin", "slide_dot", "spin_dot"}));
}

TEST(UrdfRobot, ABadEffortNamesTheFileAndTheJoint) {
  const fs::path dir = test::temporary_dir("urdf_bad_effort");
  for (const std::string effort : {"-2", "abc", "nan", "", "1e308"}) {
    const fs::path file =
        write_urdf(dir, R"(<limit lower="-1" upper="1" effort=")" + effort + R"(" velocity="1"/>)", "");
    try {
      (void)MujocoSystem::load(file.string());
      ADD_FAILURE() << "effort '" << effort << "' was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file.string()), std::string::npos) << what;
      EXPECT_NE(what.find("joint 'slide'"), std::string::npos) << what;
      EXPECT_NE(what.find("effort"), std::string::npos) << what;
    }
  }
}

TEST(UrdfRobot, AMalformedUrdfNamesTheFileAndTheLine) {
  const fs::path file = test::temporary_dir("urdf_malformed") / "broken.urdf";
  std::ofstream(file) << "<robot name=\"r\">\n  <link name=\"base\"/>\n  <joint name=\"j type=\"revolute\">\n</robot>\n";
  try {
    (void)MujocoSystem::load(file.string());
    ADD_FAILURE() << "a malformed URDF was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ": line 3"), std::string::npos) << e.what();
  }
}

/// The two-link arm's URDF with its first `type="revolute"` replaced by `type="<type>"`, or with
/// `extra` inserted after the elbow's <joint> tag.
fs::path edited_arm(const fs::path& dir, const std::string& type, const std::string& extra = "") {
  std::ifstream in(urdf_arm_path());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string revolute = "type=\"revolute\"";
  if (type != "revolute") text.replace(text.find(revolute), revolute.size(), "type=\"" + type + "\"");
  const std::string elbow = "<joint name=\"elbow\" type=\"revolute\">";
  text.insert(text.find(elbow) + elbow.size(), extra);
  const fs::path file = dir / "arm.urdf";
  std::ofstream(file) << text;
  return file;
}

/// The message MujocoSystem::load gives for `file`, "" when it loads.
std::string load_error(const fs::path& file) {
  try {
    (void)MujocoSystem::load(file.string());
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// MuJoCo's URDF reader crashes the process on a joint type it does not know; each is refused first,
// with the line and the joint, and the planar joint MuJoCo would split into three joints without
// motors is refused too.
TEST(UrdfRobot, AJointTypeOutsideUrdfsListIsAnErrorNamingTheLineAndTheJoint) {
  const fs::path dir = test::temporary_dir("urdf_joint_type");
  for (const std::string type : {"Revolute", "revolute ", "", "ball", "spherical", "planar"}) {
    const fs::path file = edited_arm(dir, type);
    const std::string what = load_error(file);
    EXPECT_NE(what.find(file.string() + ": line 22: joint 'shoulder'"), std::string::npos) << type << ": " << what;
    EXPECT_NE(what.find(type == "planar" ? "two prismatic joints and a revolute one"
                                         : "expected one of revolute, continuous, prismatic, fixed, floating"),
              std::string::npos)
        << type << ": " << what;
  }
}

/// `file`'s text with `from` replaced by `to` (which must occur), written to dir / name.
fs::path replaced(const fs::path& file, const std::string& from, const std::string& to, const fs::path& dir,
                  const std::string& name) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  const fs::path out = dir / name;
  std::ofstream(out) << text;
  return out;
}

double parameter_value(const MujocoSystem& system, const std::string& name) {
  for (const Parameter& p : system.parameters())
    if (p.name == name) return p.value;
  ADD_FAILURE() << "no parameter " << name;
  return 0.0;
}

// A URDF reaches MuJoCo through its MJCF writer, which keeps 6 significant digits and writes an
// integral value beyond 2^31 as -2147483648: the model simulates the file's own numbers.
TEST(UrdfRobot, TheFilesNumbersReachTheModelToTheLastDigit) {
  const fs::path dir = test::temporary_dir("urdf_digits");
  const fs::path mass = replaced(urdf_arm_path(), R"(<mass value="1.0"/>)", R"(<mass value="1.23456789012345"/>)", dir,
                                 "mass.urdf");
  const fs::path both = replaced(mass, R"(<dynamics damping="0.05"/>)", R"(<dynamics damping="3000000000"/>)", dir,
                                 "both.urdf");
  const auto arm = MujocoSystem::load(both.string());
  EXPECT_EQ(parameter_value(*arm, "upper_arm.mass"), 1.23456789012345);
  EXPECT_EQ(parameter_value(*arm, "shoulder.damping"), 3e9);
  EXPECT_EQ(parameter_value(*arm, "elbow.damping"), 0.05);
  EXPECT_EQ(arm->control_dim(), 2);  // the motors of the converted model are there
}

// MuJoCo takes a NaN with a warning and drops some numbers without a word (a NaN rpy becomes no
// rotation, lower > upper no limits, a NaN axis the default one): each is refused naming the line.
TEST(UrdfRobot, ANumberMujocoWouldDropOrTakeWithAWarningIsRefusedNamingTheLine) {
  const fs::path dir = test::temporary_dir("urdf_numbers");
  const std::string arm = urdf_arm_path();
  const struct {
    std::string from, to, expected;
  } cases[] = {
      {R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="nan 1 0"/>)", R"(: line 26: <axis xyz="nan 1 0">; expected 3 finite numbers)"},
      {R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="0 1"/>)", R"(: line 26: <axis xyz="0 1">; expected 3 finite numbers)"},
      {R"(<origin xyz="0 0 -0.5"/>)", R"(<origin xyz="0 0 -0.5" rpy="nan 0 0"/>)", R"(: line 33: <origin rpy="nan 0 0">)"},
      {R"(<mass value="1.0"/>)", R"(<mass value="abc"/>)", R"(: line 11: <mass value="abc">; expected 1 finite number)"},
      {R"(ixx="0.021")", R"(ixx="inf")", R"(: line 12: <inertia ixx="inf">)"},
      {R"(lower="-3.0" upper="3.0")", R"(lower="3.0" upper="-3.0")", R"(: line 27: <limit lower="3.0" upper="-3.0">; expected lower <= upper)"},
      {R"(<dynamics damping="0.05"/>)", R"(<dynamics damping="-5"/>)", R"(: line 28: <dynamics damping="-5">; expected a value >= 0)"},
      {R"(<dynamics damping="0.05"/>)", R"(<dynamics damping="0.05" friction="-1"/>)", R"(: line 28: <dynamics friction="-1">; expected a value >= 0)"},
  };
  for (const auto& c : cases) {
    const fs::path file = replaced(arm, c.from, c.to, dir, "arm.urdf");
    EXPECT_NE(load_error(file).find(file.string() + c.expected), std::string::npos) << c.to << ": " << load_error(file);
  }
}

// The same in an MJCF model, after MuJoCo compiled it: a NaN (read with a warning only), a negative
// damping, armature or friction loss.
TEST(MujocoModelNumbers, ANumberThatIsNotFiniteOrAddsEnergyIsRefusedNamingTheJoint) {
  const fs::path dir = test::temporary_dir("mjcf_numbers");
  const std::string pendulum = pendulum_path();
  const struct {
    std::string from, to, expected;
  } cases[] = {
      {R"(axis="0 1 0")", R"(axis="0 nan 0")", "joint 'swing': jnt_axis is (nan, nan, nan); expected finite numbers"},
      {R"(damping="0.02")", R"(damping="-0.02")", "joint 'swing': damping is -0.02; expected a value >= 0"},
      {R"(damping="0.02")", R"(damping="0.02" armature="-1")", "joint 'swing': armature is -1; expected a value >= 0"},
      {R"(damping="0.02")", R"(damping="0.02" frictionloss="-1")", "joint 'swing': frictionloss is -1; expected a value >= 0"},
      {R"(gravity="0 0 -9.81")", R"(gravity="0 0 nan")", "<option gravity>: entry 2 is nan; expected finite numbers"},
  };
  for (const auto& c : cases) {
    const fs::path file = replaced(pendulum, c.from, c.to, dir, "pendulum.xml");
    EXPECT_NE(load_error(file).find(file.string() + ": " + c.expected), std::string::npos) << c.to << ": " << load_error(file);
  }
}

// <mimic>: the follower has no motor and its acceleration follows the leader's, q_e = 0.5 q_s + 0.1
// (MuJoCo's joint equality); without the mimic the elbow swings back against the shoulder.
TEST(UrdfRobot, AMimicJointFollowsItsLeaderAndHasNoMotor) {
  const fs::path dir = test::temporary_dir("urdf_mimic");
  const auto arm =
      MujocoSystem::load(edited_arm(dir, "revolute", R"(<mimic joint="shoulder" multiplier="0.5" offset="0.1"/>)").string());
  EXPECT_EQ(names_of(arm->controls()), (std::vector<std::string>{"shoulder_motor"}));
  Vector xdot(4);
  const Vector on_constraint = (Vector(4) << 0.4, 0.3, 0.0, 0.0).finished();
  arm->evaluate(on_constraint, (Vector(1) << 4.0).finished(), xdot, nullptr);
  EXPECT_GT(std::abs(xdot(2)), 1.0);
  EXPECT_NEAR(xdot(3), 0.5 * xdot(2), 0.05 * std::abs(xdot(2)));
  const auto free_arm = MujocoSystem::load(urdf_arm_path());
  free_arm->evaluate(on_constraint, (Vector(2) << 4.0, 0.0).finished(), xdot, nullptr);
  EXPECT_LT(xdot(3) * xdot(2), 0.0);

  for (const auto& [mimic, expected] :
       std::vector<std::pair<std::string, std::string>>{
           {R"(<mimic joint="wrist"/>)", "mimics 'wrist': no joint of the file has that name"},
           {R"(<mimic joint="elbow"/>)", "a joint cannot follow itself"},
           {R"(<mimic joint="shoulder" multiplier="nan"/>)", "<mimic multiplier=\"nan\">; expected a finite number"},
           {R"(<mimic/>)", "<mimic> without a joint"}}) {
    const std::string what = load_error(edited_arm(dir, "revolute", mimic));
    EXPECT_NE(what.find("joint 'elbow'"), std::string::npos) << mimic << ": " << what;
    EXPECT_NE(what.find(expected), std::string::npos) << mimic << ": " << what;
  }
}

MeasurementSet passive_set() {
  MeasurementSet set;
  set.system = MujocoSystem::load(pendulum_path())->signature();
  for (long id = 0; id < 2; ++id) {
    Episode e;
    e.id = id;
    e.t = Vector::LinSpaced(5, 0.0, 0.08);
    e.x = Matrix::Random(5, 2);
    e.u = Matrix(5, 0);
    set.episodes.push_back(e);
  }
  return set;
}

TEST(PassiveSystem, MeasurementFilesWithoutControlColumnsRoundTrip) {
  const fs::path dir = test::temporary_dir("passive_files");
  const MeasurementSet set = passive_set();
  for (const char* name : {"swing.csv", "swing.h5"}) {
    write_measurements(dir / name, set);
    const MeasurementSet back = read_measurements(dir / name, set.system);
    ASSERT_EQ(back.episodes.size(), 2u);
    EXPECT_EQ(back.episodes[1].u.rows(), 5);
    EXPECT_EQ(back.episodes[1].u.cols(), 0);
    EXPECT_MATRIX_NEAR(back.episodes[1].x, set.episodes[1].x, 1e-12);
  }
  std::ifstream csv(dir / "swing.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "episode,t,swing,swing_dot");
}

TEST(PassiveSystem, AnHdf5FileWithoutControlNamesOrUIsRead) {
  const fs::path file = test::temporary_dir("passive_h5_minimal") / "swing.h5";
  {
    H5::H5File h5(file.string(), H5F_ACC_TRUNC);
    const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
    const char* system[] = {"pendulum_passive"};
    h5.openGroup("/").createAttribute("system", type, H5::DataSpace(H5S_SCALAR)).write(type, system);
    const char* states[] = {"swing", "swing_dot"};
    const hsize_t two[1] = {2};
    h5.openGroup("/").createAttribute("state_names", type, H5::DataSpace(1, two)).write(type, states);
    H5::Group episode = h5.createGroup("episodes").createGroup("0");
    const double t[3] = {0.0, 0.02, 0.04}, x[6] = {0.1, 0.0, 0.09, -0.1, 0.08, -0.2};
    const hsize_t tdims[1] = {3}, xdims[2] = {3, 2};
    episode.createDataSet("t", H5::PredType::IEEE_F64LE, H5::DataSpace(1, tdims)).write(t, H5::PredType::NATIVE_DOUBLE);
    episode.createDataSet("x", H5::PredType::IEEE_F64LE, H5::DataSpace(2, xdims)).write(x, H5::PredType::NATIVE_DOUBLE);
  }
  const MeasurementSet set = read_measurements(file, MujocoSystem::load(pendulum_path())->signature());
  ASSERT_EQ(set.episodes.size(), 1u);
  EXPECT_EQ(set.episodes[0].u.rows(), 3);
  EXPECT_EQ(set.episodes[0].u.cols(), 0);
}

}  // namespace
}  // namespace gpilqg
