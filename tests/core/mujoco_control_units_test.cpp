// The unit of a MuJoCo actuator's control, from its transmission and its gain and bias
// (core/src/mujoco_actuator_units.hpp): small MJCF models written here, each actuator's unit the one a
// person reads off the model (a motor on a hinge takes a torque, a position servo an angle, ...), and
// "-" where the model does not say.

#include <gtest/gtest.h>

#include "gpilqg/core/mujoco_system.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

/// A chain of bodies, one joint each (hinges h1..h4, slides s1..s3), with a site and a fixed tendon,
/// and the given <actuator> section.
std::string chain_model(const std::string& actuators) {
  std::string bodies, close;
  const char* joints[] = {"hinge h1", "hinge h2", "hinge h3", "hinge h4", "slide s1", "slide s2", "slide s3"};
  for (const char* joint : joints) {
    const std::string text(joint);
    const std::string type = text.substr(0, text.find(' ')), name = text.substr(text.find(' ') + 1);
    bodies += "<body pos=\"0 0 -0.1\"><joint name=\"" + name + "\" type=\"" + type +
              "\" axis=\"0 1 0\"/><geom type=\"sphere\" size=\"0.02\" mass=\"0.1\"/>";
    close += "</body>";
  }
  return R"(<mujoco model="units"><option timestep="0.01"/><default><geom contype="0" conaffinity="0"/></default>
<worldbody><site name="tip"/>)" +
         bodies + close + R"(</worldbody>
<tendon><fixed name="pair"><joint joint="h1" coef="1"/><joint joint="h2" coef="1"/></fixed></tendon>
<actuator>)" + actuators +
         "</actuator></mujoco>\n";
}

std::vector<std::string> control_units(const std::string& actuators) {
  const auto file = test::write_text(test::temporary_dir("control_units") / "model.xml", chain_model(actuators));
  std::vector<std::string> units;
  // The system held for the loop: the controls are a member of it.
  const auto system = MujocoSystem::load(file.string());
  for (const Quantity& q : system->controls()) units.push_back(q.unit);
  return units;
}

TEST(MujocoControlUnits, AMotorTakesATorqueOnAHingeAndAForceOnASlideWhateverItsGear) {
  EXPECT_EQ(control_units(R"(<motor name="m1" joint="h1" gear="1"/>
                             <motor name="m50" joint="h2" gear="50"/>
                             <motor name="geared_down" joint="h3" gear="0.2"/>
                             <motor name="linear" joint="s1"/>
                             <motor name="linear50" joint="s2" gear="50"/>)"),
            (std::vector<std::string>{"N m", "N m", "N m", "N", "N"}));
}

TEST(MujocoControlUnits, AServoTakesItsSetPoint) {
  EXPECT_EQ(control_units(R"(<position name="angle" joint="h1" kp="20"/>
                             <position name="angle_geared" joint="h2" kp="5" gear="3"/>
                             <position name="length" joint="s1" kp="100"/>
                             <velocity name="rate" joint="h3" kv="2"/>
                             <velocity name="speed" joint="s2" kv="7"/>)"),
            (std::vector<std::string>{"rad", "rad", "m", "rad/s", "m/s"}));
}

TEST(MujocoControlUnits, AGeneralActuatorAtItsDefaultsIsAMotor) {
  // <general> with no gain or bias given is compiled exactly like <motor>: force = ctrl.
  EXPECT_EQ(control_units(R"(<general name="plain" joint="h1"/><general name="plain_slide" joint="s1" gear="4"/>)"),
            (std::vector<std::string>{"N m", "N"}));
}

TEST(MujocoControlUnits, NothingIsClaimedWhereTheModelDoesNotSayWhatTheControlIs) {
  EXPECT_EQ(control_units(R"(<general name="scaled" joint="h1" gainprm="2.5"/>
                             <general name="own_bias" joint="h2" gainprm="5" biastype="affine" biasprm="1 -5 0"/>
                             <general name="spring" joint="h3" gainprm="4" biastype="affine" biasprm="0 -3 0"/>
                             <general name="affine_gain" joint="h4" gaintype="affine" gainprm="1 0 -1"/>
                             <motor name="on_tendon" tendon="pair"/>
                             <motor name="on_site" site="tip" gear="0 0 1 0 0 0"/>)"),
            (std::vector<std::string>(6, "-")));
}

}  // namespace
}  // namespace gpilqg
