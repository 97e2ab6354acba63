#pragma once
/// @file result_files.hpp
/// Two result files of `gpilqg run` (run_results_io.hpp) compared as the resume and merge tests need:
/// a resumed run, or a merge of separate runs, must write the file one uninterrupted run writes, up to
/// the wall-clock times and the `created` stamp.

#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpilqg/core/hdf5_reader.hpp"

namespace gpilqg::test {

/// The datasets that measure wall-clock time: time_* and iter_<k>/solve_time.
inline bool is_timing_dataset(const std::string& path) {
  const std::string leaf = path.substr(path.find_last_of('/') + 1);
  return leaf.rfind("time_", 0) == 0 || leaf == "solve_time";
}

/// An attribute's value as text, whatever its type (strings, lists of strings, numbers).
inline std::string attribute_text(const Hdf5Reader& h5, const std::string& object, const std::string& name) {
  std::string text;
  try {
    for (const auto& s : h5.string_list_attribute(object, name)) text += "'" + s + "' ";
  } catch (const std::runtime_error&) {
    for (const double v : h5.number_list_attribute(object, name)) text += std::to_string(v) + " ";
  }
  return text;
}

/// Every dataset (names, shapes, values bit for bit) but the wall-clock times; every attribute of
/// the root and of each group holding datasets but the root's `created`; the soft link of each task.
inline void expect_same_result_files(const std::filesystem::path& actual, const std::filesystem::path& expected) {
  const Hdf5Reader a(actual), b(expected);
  const auto names = b.datasets();
  ASSERT_EQ(a.datasets(), names);
  int compared = 0;
  std::set<std::string> groups = {"/"};
  for (const auto& name : names) {
    for (std::size_t slash = name.find('/', 1); slash != std::string::npos; slash = name.find('/', slash + 1))
      groups.insert(name.substr(0, slash));
    if (is_timing_dataset(name)) continue;
    EXPECT_EQ(a.shape(name), b.shape(name)) << name;
    const auto x = a.read_array(name), y = b.read_array(name);
    EXPECT_TRUE(x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0) << name;
    ++compared;
  }
  EXPECT_GT(compared, 100);
  for (const auto& group : groups) {
    ASSERT_EQ(a.attributes(group), b.attributes(group)) << group;
    for (const auto& attribute : b.attributes(group)) {
      if (group == "/" && attribute == "created") continue;
      EXPECT_EQ(attribute_text(a, group, attribute), attribute_text(b, group, attribute)) << group << "@" << attribute;
    }
    if (group != "/" && group.find('/', 1) == std::string::npos) {
      EXPECT_EQ(a.soft_link_target(group + "/gp_ilqg"), b.soft_link_target(group + "/gp_ilqg")) << group;
    }
  }
}

}  // namespace gpilqg::test
