// The system registry: fixed names, presets, parameter overrides and their errors.

#include <gtest/gtest.h>

#include "gpilqg/core/systems.hpp"

namespace gpilqg {
namespace {

double parameter(const Dynamics& d, const std::string& name) {
  for (const auto& p : d.parameters())
    if (p.name == name) return p.value;
  ADD_FAILURE() << "no parameter " << name;
  return 0.0;
}

TEST(Systems, RegistryHoldsTheFixedNames) {
  EXPECT_EQ(system_names(), (std::vector<std::string>{"cartpole", "quadrotor"}));
  for (const auto& name : system_names()) EXPECT_EQ(make_system(name)->name(), name);
  const auto quad = system_signature("quadrotor");
  EXPECT_EQ(names_of(quad.states), (std::vector<std::string>{"px", "py", "pz", "vx", "vy", "vz", "rx",
                                                              "ry", "rz", "wx", "wy", "wz"}));
  EXPECT_EQ(names_of(quad.controls), (std::vector<std::string>{"u1", "u2", "u3", "u4"}));
}

TEST(Systems, PresetsDifferOnlyWhereThePaperSays) {
  auto sim = make_system("cartpole", Preset::Simulator), real = make_system("cartpole", Preset::RealWorld);
  EXPECT_DOUBLE_EQ(parameter(*sim, "pole_length"), 1.0);
  EXPECT_DOUBLE_EQ(parameter(*real, "pole_length"), 1.3);
  EXPECT_DOUBLE_EQ(parameter(*real, "cart_mass"), parameter(*sim, "cart_mass"));
  auto qsim = make_system("quadrotor", Preset::Simulator), qreal = make_system("quadrotor", Preset::RealWorld);
  EXPECT_DOUBLE_EQ(parameter(*qsim, "mass"), 0.5);
  EXPECT_DOUBLE_EQ(parameter(*qreal, "mass"), 0.7);
  for (const char* same : {"kv", "km", "inertia", "rho"})
    EXPECT_DOUBLE_EQ(parameter(*qsim, same), parameter(*qreal, same)) << same;
  EXPECT_DOUBLE_EQ(parameter(*qsim, "kv"), 0.15);
  EXPECT_DOUBLE_EQ(parameter(*qsim, "km"), 0.025);
  EXPECT_DOUBLE_EQ(parameter(*qsim, "inertia"), 0.05);
  EXPECT_DOUBLE_EQ(parameter(*qsim, "rho"), 0.17);
  EXPECT_EQ(parse_preset("sim"), Preset::Simulator);
  EXPECT_EQ(parse_preset("real"), Preset::RealWorld);
  EXPECT_FALSE(parse_preset("simulator").has_value());
}

TEST(Systems, OverridesSetNamedParameters) {
  auto cp = make_system("cartpole", Preset::Simulator, {{"pole_length", 1.7}, {"cart_mass", 2.0}});
  EXPECT_DOUBLE_EQ(parameter(*cp, "pole_length"), 1.7);
  EXPECT_DOUBLE_EQ(parameter(*cp, "cart_mass"), 2.0);
}

TEST(Systems, UnknownNamesListTheValidChoices) {
  try {
    make_system("pendulum");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'pendulum'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cartpole, quadrotor"), std::string::npos) << e.what();
  }
  try {
    make_system("quadrotor", Preset::Simulator, {{"length", 1.0}});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'length'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("mass, kv, km, inertia, rho"), std::string::npos) << e.what();
  }
  EXPECT_THROW(make_system("cartpole", Preset::Simulator, {{"pole_mass", -1.0}}), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
