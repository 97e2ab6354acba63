// The plugin loader (plugin.hpp) on the example acrobot plugin and on plugins broken in each way it
// reports: the systems join the one registry with their effects, a second load is a no-op, and every
// failure is a PluginError naming the file, registering nothing.

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/generalised_forces.hpp"
#include "gpilqg/core/plugin.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

const fs::path kAcrobot = GPILQG_ACROBOT_PLUGIN;
const fs::path kPlugins = GPILQG_TEST_PLUGIN_DIR;

fs::path test_plugin(const std::string& name) { return kPlugins / ("lib" + name + ".so"); }

bool registered(const std::string& name) {
  for (const std::string& n : SystemRegistry::instance().names())
    if (n == name) return true;
  return false;
}

/// The PluginError message of loading `path`; fails the test when it loads.
std::string load_error(const fs::path& path) {
  try {
    load_plugin(path);
  } catch (const PluginError& e) {
    return e.what();
  }
  ADD_FAILURE() << path << " loaded";
  return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(Plugin, AcrobotJoinsTheRegistryWithItsEffects) {
  const PluginInfo info = load_plugin(kAcrobot);
  EXPECT_EQ(info.path, kAcrobot.string());
  ASSERT_EQ(info.systems, std::vector<std::string>{"acrobot"});
  const SystemEntryPtr entry = find_system("acrobot");
  EXPECT_EQ(entry->origin, kAcrobot.string());
  EXPECT_EQ(system_names().back(), "acrobot");

  const DynamicsPtr real = make_system("acrobot", Preset::RealWorld);
  EXPECT_EQ(real->name(), "acrobot");
  EXPECT_EQ(real->signature().states[2].name, "theta1_dot");
  EXPECT_NE(dynamic_cast<const GeneralisedForceInput*>(real.get()), nullptr);
  for (const Parameter& p : real->parameters()) {
    if (p.name == "link2_mass") {
      EXPECT_DOUBLE_EQ(p.value, 1.3);
    }
  }
  const DynamicsPtr heavier = make_system("acrobot", Preset::Simulator, {{"link1_mass", 2.0}});
  EXPECT_DOUBLE_EQ(heavier->parameters()[0].value, 2.0);
  EXPECT_THROW(make_system("acrobot", Preset::Simulator, {{"mass", 2.0}}), std::invalid_argument);

  for (const char* name : {"joint_viscous_damping:theta1", "joint_viscous_damping:theta2",
                           "joint_coulomb_friction:theta1", "joint_coulomb_friction:theta2", "actuator_gain",
                           "input_delay", "param:link1_mass", "param:link2_mass", "param:link1_length", "param:link2_length",
                           "constant_force:theta1", "constant_force:theta2"})
    EXPECT_NO_THROW(find_effect("acrobot", name)) << name;
  EXPECT_EQ(effect_library("acrobot").size(), 12u);

  // The library works on the plugin's system like on a built-in one.
  ModelSpec world;
  world.system = "acrobot";
  world = world.with(find_effect("acrobot", "joint_viscous_damping:theta2"), Vector::Constant(1, 0.5));
  const DynamicsPtr damped = world.build();
  Vector x(4);
  x << 0.3, -0.2, 0.0, 2.0;
  const Vector u = Vector::Zero(1);
  Matrix W;
  dynamic_cast<const GeneralisedForceInput&>(*make_system("acrobot")).generalised_force_map(x, W, nullptr);
  const Vector expected = make_system("acrobot")->f(x, u) + W.col(1) * (-0.5 * 2.0);
  EXPECT_TRUE(test::matrices_near(damped->f(x, u), expected, 1e-12, 1e-12));
}

TEST(Plugin, LoadingTheSameFileAgainRegistersNothing) {
  const PluginInfo first = load_plugin(kAcrobot);
  const std::size_t count = system_names().size();
  const PluginInfo again = load_plugin(kAcrobot.parent_path() / "." / kAcrobot.filename());
  EXPECT_EQ(again.systems, first.systems);
  EXPECT_EQ(system_names().size(), count);
}

TEST(Plugin, MissingFileIsNamed) {
  const std::string message = load_error("/nonexistent/libnothing.so");
  EXPECT_TRUE(contains(message, "plugin '/nonexistent/libnothing.so': no such file")) << message;
}

TEST(Plugin, FileThatIsNotALibraryGivesDlerror) {
  const fs::path dir = test::temporary_dir("plugin_not_a_library");
  const fs::path file = dir / "libtext.so";
  std::ofstream(file) << "not a shared library\n";
  const std::string message = load_error(file);
  EXPECT_TRUE(contains(message, "plugin '" + file.string() + "' cannot be loaded: ")) << message;
  EXPECT_TRUE(contains(message, "invalid ELF header") || contains(message, "file too short")) << message;
  fs::remove_all(dir);
}

TEST(Plugin, LibraryWithoutEntryPointsIsNotAPlugin) {
  const std::string message = load_error(test_plugin("no_entry_plugin"));
  EXPECT_TRUE(contains(message, "is not a gpilqg plugin")) << message;
  EXPECT_TRUE(contains(message, "GPILQG_PLUGIN")) << message;
}

TEST(Plugin, OtherVersionIsRefusedBeforeRegistration) {
  // Its registration would abort the process.
  const std::string message = load_error(test_plugin("wrong_version_plugin"));
  const std::string next = plugin_abi_version(kPluginAbi + 1'000u);
  EXPECT_TRUE(contains(message, "was built against gpilqg " + next + ", but this is gpilqg " + kVersionString))
      << message;
  EXPECT_TRUE(contains(message, test_plugin("wrong_version_plugin").string())) << message;
}

TEST(Plugin, MissingSymbolSuggestsAnotherVersion) {
  const std::string message = load_error(test_plugin("missing_symbol_plugin"));
  EXPECT_TRUE(contains(message, "cannot be loaded: ")) << message;
  EXPECT_TRUE(contains(message, "undefined symbol")) << message;
  EXPECT_TRUE(contains(message, "was it built against another gpilqg than " + std::string(kVersionString))) << message;
}

TEST(Plugin, ThrowingRegistrationIsReportedAndRegistersNothing) {
  const std::string message = load_error(test_plugin("throwing_plugin"));
  EXPECT_TRUE(contains(message, "failed to register its systems: pendulum: calibration file 'pendulum.yaml' not found"))
      << message;
  EXPECT_FALSE(registered("pendulum"));
}

TEST(Plugin, NameOfABuiltInIsRefusedNamingBothOrigins) {
  const fs::path twin = test_plugin("cartpole_twin_plugin");
  const std::string message = load_error(twin);
  EXPECT_TRUE(contains(message, "system 'cartpole' is registered twice: by built-in and by " + twin.string()))
      << message;
  EXPECT_EQ(find_system("cartpole")->origin, "built-in");
}

TEST(Plugin, NameOfAnotherPluginIsRefusedNamingBothOrigins) {
  load_plugin(kAcrobot);
  const fs::path twin = test_plugin("acrobot_twin_plugin");
  const std::string message = load_error(twin);
  EXPECT_TRUE(contains(message, "system 'acrobot' is registered twice: by " + kAcrobot.string() + " and by " +
                                    twin.string()))
      << message;
}

TEST(Plugin, VersionNumbersReadAsVersions) {
  EXPECT_EQ(plugin_abi_version(2'013'004u), "2.13.4");
  EXPECT_EQ(plugin_abi_version(kPluginAbi), kVersionString);
}

}  // namespace
}  // namespace gpilqg
