#pragma once
/// @file arm_model.hpp
/// data/two_link_arm.xml for the MuJoCo command-line tests, and a second model file of the same arm
/// with other physics (the "real world" given as a file).

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "test_support.hpp"

namespace gpilqg::test {

inline std::filesystem::path arm_model() { return source_dir() / "data" / "two_link_arm.xml"; }

/// data/two_link_arm.xml with the forearm's mass and inertia scaled by `scale` and the elbow's damping
/// set to `damping`: what the parameters forearm.mass and elbow.damping do, as a second file in `dir`.
inline std::filesystem::path changed_arm(const std::filesystem::path& dir, double scale, double damping) {
  std::ifstream in(arm_model());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  };
  replace(R"(<joint name="elbow" type="hinge" axis="0 1 0" damping="0.05"/>)",
          fmt::format(R"(<joint name="elbow" type="hinge" axis="0 1 0" damping="{}"/>)", damping));
  replace(R"(mass="0.6" diaginertia="0.008 0.008 0.0005")",
          fmt::format(R"(mass="{}" diaginertia="{} {} {}")", 0.6 * scale, 0.008 * scale, 0.008 * scale, 0.0005 * scale));
  const std::filesystem::path file = dir / "heavier_arm.xml";
  std::ofstream(file) << text;
  return file;
}

}  // namespace gpilqg::test
