// The system registry: fixed names, presets, parameter overrides and their errors.

#include <gtest/gtest.h>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/system_registry.hpp"
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
  const auto names = system_names();  // built-ins first; a test below registers one more
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names[0], "cartpole");
  EXPECT_EQ(names[1], "quadrotor");
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

TEST(SystemRegistry, EntriesDescribeTheirSystems) {
  const auto cartpole = find_system("cartpole");
  EXPECT_EQ(cartpole->presets, (std::vector<std::string>{"sim", "real"}));
  std::vector<std::string> parameters;
  for (const auto& p : cartpole->parameters) parameters.push_back(p.name);
  EXPECT_EQ(parameters, (std::vector<std::string>{"cart_mass", "pole_mass", "pole_length", "gravity"}));
  EXPECT_TRUE(cartpole->generalised_forces);
  EXPECT_FALSE(cartpole->effects.empty());
  EXPECT_NE(cartpole->default_run_config.find("[[tasks]]"), std::string::npos);
  EXPECT_TRUE(find_system("quadrotor")->generalised_forces);
}

TEST(SystemRegistry, AnEntryAddedAtRunTimeWorksEverywhereByName) {
  SystemEntry entry;
  entry.name = "long_pole_cartpole";
  entry.origin = "systems_test";
  entry.build = [](Preset, const std::map<std::string, double>&, const ActuatorNoise& noise) -> DynamicsPtr {
    CartPoleParameters p;
    p.pole_length = 2.0;
    auto system = std::make_shared<CartPole>(p);
    system->set_noise_model(noise);
    return system;
  };
  SystemRegistry::instance().add(entry);
  EXPECT_EQ(make_system("long_pole_cartpole")->parameters()[2].value, 2.0);
  EXPECT_EQ(find_system("long_pole_cartpole")->parameters[2].value, 2.0);  // filled at registration
  // A second registration of the name is refused, naming both origins.
  entry.origin = "another plugin";
  try {
    SystemRegistry::instance().add(entry);
    FAIL() << "a duplicate name was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("by systems_test and by another plugin"), std::string::npos) << e.what();
  }
}

TEST(SystemRegistry, BadEntriesAreRefusedAtRegistration) {
  SystemEntry broken;
  broken.name = "broken_system";
  broken.origin = "systems_test";
  broken.build = [](Preset, const std::map<std::string, double>&, const ActuatorNoise&) -> DynamicsPtr {
    throw std::runtime_error("no such hardware");
  };
  try {
    SystemRegistry::instance().add(broken);
    FAIL() << "a builder that throws was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("system 'broken_system' (systems_test) cannot be built: no such hardware"),
              std::string::npos)
        << e.what();
  }
  SystemEntry file_like = broken;
  file_like.name = "robot.xml";
  EXPECT_THROW(SystemRegistry::instance().add(file_like), std::invalid_argument);
  SystemEntry no_builder;
  no_builder.name = "nothing";
  EXPECT_THROW(SystemRegistry::instance().add(no_builder), std::invalid_argument);
  EXPECT_TRUE(is_model_file_name("arm.XML"));
  EXPECT_TRUE(is_model_file_name("dir/robot.urdf"));
  EXPECT_FALSE(is_model_file_name("cartpole"));
}

}  // namespace
}  // namespace gpilqg
