// `gpilqg COMMAND --plugin LIB.so`: the example acrobot plugin through the command line (synthetic data
// with a hidden effect, then the diagnosis names it), `--plugin` before and after the command's name
// and in nested commands, and every way a plugin can fail: exit 2, "error:", the file named.

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "gpilqg/core/plugin.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::quote;

const fs::path kAcrobot = GPILQG_ACROBOT_PLUGIN;
const fs::path kPlugins = GPILQG_TEST_PLUGIN_DIR;

fs::path test_plugin(const std::string& name) { return kPlugins / ("lib" + name + ".so"); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// Runs a command that must fail on its plugin before it starts: exit 2 and one "error: " line.
std::string plugin_error(const std::string& plugin_options) {
  const auto result = test::run_cli("solve /nonexistent/problem.toml " + plugin_options);
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_EQ(result.err.rfind("error: plugin '", 0), 0u) << result.err;
  EXPECT_TRUE(result.out.empty()) << result.out;
  return result.err;
}

TEST(PluginCli, HiddenDampingOfTheAcrobotIsFoundThroughThePlugin) {
  const fs::path dir = test::temporary_dir("plugin_cli");
  const fs::path data = dir / "acrobot.csv";
  const auto simulated = test::run_cli("simulate --plugin " + quote(kAcrobot) +
                                       " --system acrobot --preset sim --effect joint_viscous_damping:theta2=0.3 "
                                       "--out " + quote(data));
  ASSERT_EQ(simulated.status, 0) << simulated.err;
  EXPECT_TRUE(contains(simulated.out, "acrobot sim preset")) << simulated.out;

  // The option after the command's options, as the documentation writes it.
  const auto diagnosed = test::run_cli("diagnose --system acrobot --data " + quote(data) +
                                       " --json --gp-points 100 --gp-restarts 0 --plugin " + quote(kAcrobot));
  ASSERT_EQ(diagnosed.status, 0) << diagnosed.err;
  const json j = json::parse(diagnosed.out);
  EXPECT_EQ(j["system"], "acrobot");
  EXPECT_EQ(j["verdict"]["status"], "explained") << j["verdict"].dump();
  EXPECT_EQ(j["verdict"]["effect"], "joint_viscous_damping:theta2") << j["verdict"].dump();
  EXPECT_NEAR(j["verdict"]["parameters"]["b"].get<double>(), 0.3, 0.15 * 0.3) << j["verdict"].dump();

  // The suggested next command loads the plugin too.
  const auto text = test::run_cli("--plugin " + quote(kAcrobot) + " diagnose --system acrobot --data " + quote(data) +
                                  " --gp-points 100 --gp-restarts 0");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_TRUE(contains(text.out, "next: gpilqg diagnose --plugin " + kAcrobot.string() + " --system acrobot --data " +
                                     data.string() + " --add joint_viscous_damping:theta2"))
      << text.out;
  fs::remove_all(dir);
}

// A plugin system's coordinates follow the "Q_<c>" convention, so its users declare effects in a model
// file too: a hidden torsion spring at the elbow, simulated from a model file as the world and found
// when the diagnosis's model file declares it.
TEST(PluginCli, AUserEffectOnAPluginSystemIsSimulatedAndFound) {
  const fs::path dir = test::temporary_dir("plugin_user_effect");
  const std::string declaration = "[model]\nsystem = \"acrobot\"\n\n[[user_effects]]\nname = \"elbow_spring\"\n"
                                  "coordinate = \"theta2\"\nterms = [\"sin(q)\"]\nparameters = [\"k\"]\n";
  std::ofstream(dir / "world.toml") << declaration << "\n[effects]\nelbow_spring = -0.4\n";
  std::ofstream(dir / "user.toml") << declaration;
  const fs::path data = dir / "acrobot.csv";
  const std::string plugin = " --plugin " + quote(kAcrobot);
  const auto simulated = test::run_cli("simulate" + plugin + " --system acrobot --world-model " + quote(dir / "world.toml") +
                                       " --out " + quote(data));
  ASSERT_EQ(simulated.status, 0) << simulated.err;
  EXPECT_TRUE(contains(simulated.out, "acrobot model file")) << simulated.out;
  const auto diagnosed = test::run_cli("diagnose" + plugin + " --system acrobot --data " + quote(data) + " --model " +
                                       quote(dir / "user.toml") + " --json --gp-points 100 --gp-restarts 0");
  ASSERT_EQ(diagnosed.status, 0) << diagnosed.err;
  const json j = json::parse(diagnosed.out);
  EXPECT_EQ(j["verdict"]["status"], "explained") << j["verdict"].dump();
  EXPECT_EQ(j["verdict"]["effect"], "elbow_spring") << j["verdict"].dump();
  EXPECT_NEAR(j["verdict"]["parameters"]["k"].get<double>(), -0.4, 0.15 * 0.4) << j["verdict"].dump();
  fs::remove_all(dir);
}

TEST(PluginCli, OptionWorksBeforeTheCommandAndInNestedCommands) {
  const fs::path dir = test::temporary_dir("plugin_cli");
  const fs::path data = dir / "acrobot.csv";
  ASSERT_EQ(test::run_cli("--plugin " + quote(kAcrobot) + " simulate --system acrobot --episodes 2 --steps 20 --out " +
                          quote(data))
                .status,
            0);
  const auto info = test::run_cli("data info " + quote(data) + " --system acrobot --plugin " + quote(kAcrobot) +
                                  " --plugin " + quote(kAcrobot) + " --json");
  ASSERT_EQ(info.status, 0) << info.err;
  EXPECT_EQ(json::parse(info.out)["system"], "acrobot") << info.out;
  fs::remove_all(dir);
}

TEST(PluginCli, WithoutThePluginTheSystemIsUnknown) {
  const auto result = test::run_cli("simulate --system acrobot --out /nonexistent/data.csv");
  EXPECT_EQ(result.status, 2);
  EXPECT_TRUE(contains(result.err, "error: unknown system 'acrobot'")) << result.err;
  EXPECT_TRUE(contains(result.err, "--plugin")) << result.err;
}

TEST(PluginCli, MissingFile) {
  const std::string err = plugin_error("--plugin /nonexistent/libacrobot.so");
  EXPECT_TRUE(contains(err, "error: plugin '/nonexistent/libacrobot.so': no such file")) << err;
}

TEST(PluginCli, FileThatIsNotALibrary) {
  const fs::path dir = test::temporary_dir("plugin_cli");
  const fs::path file = dir / "libnotes.so";
  std::ofstream(file) << "notes, not code\n";
  const std::string err = plugin_error("--plugin " + quote(file));
  EXPECT_TRUE(contains(err, "error: plugin '" + file.string() + "' cannot be loaded: " + file.string() + ": ")) << err;
  fs::remove_all(dir);
}

TEST(PluginCli, LibraryThatIsNotAPlugin) {
  const fs::path file = test_plugin("no_entry_plugin");
  const std::string err = plugin_error("--plugin " + quote(file));
  EXPECT_TRUE(contains(err, "error: plugin '" + file.string() + "' is not a gpilqg plugin")) << err;
}

TEST(PluginCli, PluginOfAnotherVersion) {
  const fs::path file = test_plugin("wrong_version_plugin");
  const std::string err = plugin_error("--plugin " + quote(file));
  EXPECT_TRUE(contains(err, "error: plugin '" + file.string() + "' was built against gpilqg " +
                                plugin_abi_version(kPluginAbi + 1'000u) + ", but this is gpilqg " + kVersionString))
      << err;
}

TEST(PluginCli, RegistrationThatThrows) {
  const fs::path file = test_plugin("throwing_plugin");
  const std::string err = plugin_error("--plugin " + quote(file));
  EXPECT_TRUE(contains(err, "error: plugin '" + file.string() +
                                "' failed to register its systems: pendulum: calibration file 'pendulum.yaml' not "
                                "found"))
      << err;
}

TEST(PluginCli, NameOfABuiltInSystem) {
  const fs::path file = test_plugin("cartpole_twin_plugin");
  const std::string err = plugin_error("--plugin " + quote(file));
  EXPECT_TRUE(contains(err, "system 'cartpole' is registered twice: by built-in and by " + file.string())) << err;
}

TEST(PluginCli, NameOfAnotherPlugin) {
  const fs::path twin = test_plugin("acrobot_twin_plugin");
  const std::string err = plugin_error("--plugin " + quote(kAcrobot) + " --plugin " + quote(twin));
  EXPECT_TRUE(contains(err, "error: plugin '" + twin.string() + "': system 'acrobot' is registered twice: by " +
                                kAcrobot.string() + " and by " + twin.string()))
      << err;
}

}  // namespace
}  // namespace gpilqg
