#pragma once
/// @file mat_file.hpp
/// Writes small MATLAB v5 files with matio for the log-import tests: named double vectors, and
/// optionally one 1 x 1 struct of named double vectors.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <matio.h>

namespace gpilqg::test {

using MatVectors = std::vector<std::pair<std::string, std::vector<double>>>;

inline matvar_t* mat_column(const std::string& name, const std::vector<double>& values) {
  std::size_t dims[2] = {values.size(), 1};
  return Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(values.data()), 0);
}

/// `vectors` as N x 1 double variables; `struct_fields` (when not empty) as the fields of a 1 x 1
/// struct named `struct_name`.
inline void write_mat_file(const std::filesystem::path& file, const MatVectors& vectors,
                           const std::string& struct_name = "", const MatVectors& struct_fields = {}) {
  mat_t* mat = Mat_CreateVer(file.string().c_str(), nullptr, MAT_FT_MAT5);
  if (mat == nullptr) throw std::runtime_error("matio cannot create " + file.string());
  for (const auto& [name, values] : vectors) {
    matvar_t* var = mat_column(name, values);
    Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE);
    Mat_VarFree(var);
  }
  if (!struct_fields.empty()) {
    std::vector<const char*> names;
    for (const auto& field : struct_fields) names.push_back(field.first.c_str());
    names.push_back(nullptr);
    std::size_t dims[2] = {1, 1};
    matvar_t* s = Mat_VarCreateStruct2(struct_name.c_str(), 2, dims, names.data());
    for (const auto& [name, values] : struct_fields) Mat_VarSetStructFieldByName(s, name.c_str(), 0, mat_column(name, values));
    Mat_VarWrite(mat, s, MAT_COMPRESSION_NONE);
    Mat_VarFree(s);
  }
  Mat_Close(mat);
}

}  // namespace gpilqg::test
