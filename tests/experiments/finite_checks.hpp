#pragma once
/// @file finite_checks.hpp
/// Assertions that no NaN or inf reached a report: every number of a JSON document, and every
/// floating-point dataset of an HDF5 file (walked recursively). Each failure names the first offender.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace gpilqg::test {

/// Every number in `j` is finite; the failure names its JSON path (e.g. ranking[0].explained_ci95[1]).
inline ::testing::AssertionResult json_numbers_finite(const nlohmann::json& j, const std::string& path = "") {
  if (j.is_number_float() && !std::isfinite(j.get<double>()))
    return ::testing::AssertionFailure() << path << " is " << j.get<double>();
  if (j.is_object())
    for (const auto& [key, value] : j.items())
      if (auto r = json_numbers_finite(value, path + "." + key); !r) return r;
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i)
      if (auto r = json_numbers_finite(j[i], path + "[" + std::to_string(i) + "]"); !r) return r;
  return ::testing::AssertionSuccess();
}

/// Every floating-point dataset of the HDF5 file holds finite values only (and at least one dataset
/// exists); the failure names the first dataset with a NaN or inf.
/// The paths of every dataset under `group` (recursively), e.g. "compare/residual".
inline void collect_datasets(const H5::Group& group, const std::string& prefix, std::vector<std::string>& out) {
  for (hsize_t i = 0; i < group.getNumObjs(); ++i) {
    const std::string name = prefix + group.getObjnameByIdx(i);
    const H5G_obj_t type = group.getObjTypeByIdx(i);
    if (type == H5G_DATASET) out.push_back(name);
    if (type == H5G_GROUP) collect_datasets(group.openGroup(group.getObjnameByIdx(i)), name + "/", out);
  }
}

/// Every floating-point dataset of the HDF5 file holds finite values only (and at least one dataset
/// exists); the failure names the first dataset with a NaN or inf.
inline ::testing::AssertionResult hdf5_datasets_finite(const std::filesystem::path& file) {
  const H5::H5File h5(file.string(), H5F_ACC_RDONLY);
  std::vector<std::string> datasets;
  collect_datasets(h5.openGroup("/"), "", datasets);
  if (datasets.empty()) return ::testing::AssertionFailure() << file << " has no datasets";
  for (const std::string& name : datasets) {
    const H5::DataSet set = h5.openDataSet(name);
    if (set.getTypeClass() != H5T_FLOAT) continue;
    std::vector<double> values(static_cast<std::size_t>(set.getSpace().getSimpleExtentNpoints()));
    if (!values.empty()) set.read(values.data(), H5::PredType::NATIVE_DOUBLE);
    for (double v : values)
      if (!std::isfinite(v)) return ::testing::AssertionFailure() << file << ":/" << name << " holds " << v;
  }
  return ::testing::AssertionSuccess();
}

}  // namespace gpilqg::test
