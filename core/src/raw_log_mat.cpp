/// Raw MAT logs through matio (Debian libmatio-dev; MATLAB v4, v5 and v7.3 files): every real,
/// non-sparse numeric vector variable is a column; a 1 x 1 struct contributes its vector fields as
/// "struct.field" columns. Other variables are kept as unusable columns with the reason.

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <memory>

#include <hdf5.h>
#include <matio.h>

#include "gpilqg/core/hdf5_self_contained.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/raw_log.hpp"

namespace gpilqg {

namespace {

struct MatFileCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct MatVarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};
using MatFile = std::unique_ptr<mat_t, MatFileCloser>;
using MatVar = std::unique_ptr<matvar_t, MatVarFreer>;

template <typename T>
std::vector<double> to_doubles(const void* data, std::size_t count) {
  const T* values = static_cast<const T*>(data);
  return std::vector<double>(values, values + count);
}

std::string shape_of(const matvar_t& var) {
  std::string shape;
  for (int d = 0; d < var.rank; ++d) shape += (d == 0 ? "" : " x ") + std::to_string(var.dims[d]);
  return shape;
}

/// The variable as a column: its values when it is a real numeric vector, else the reason it is not.
LogColumn column_of(const matvar_t& var, const std::string& name) {
  LogColumn column{name, {}, ""};
  if (var.rank != 2 || (var.dims[0] != 1 && var.dims[1] != 1)) {
    column.unusable = fmt::format("a {} array, not a vector", shape_of(var));
    return column;
  }
  if (var.isComplex) {
    column.unusable = "complex values";
    return column;
  }
  const std::size_t count = var.dims[0] * var.dims[1];
  if (count > 0 && var.data == nullptr) {
    column.unusable = "no data";
    return column;
  }
  switch (var.class_type) {
    case MAT_C_DOUBLE: column.values = to_doubles<double>(var.data, count); break;
    case MAT_C_SINGLE: column.values = to_doubles<float>(var.data, count); break;
    case MAT_C_INT8: column.values = to_doubles<std::int8_t>(var.data, count); break;
    case MAT_C_UINT8: column.values = to_doubles<std::uint8_t>(var.data, count); break;
    case MAT_C_INT16: column.values = to_doubles<std::int16_t>(var.data, count); break;
    case MAT_C_UINT16: column.values = to_doubles<std::uint16_t>(var.data, count); break;
    case MAT_C_INT32: column.values = to_doubles<std::int32_t>(var.data, count); break;
    case MAT_C_UINT32: column.values = to_doubles<std::uint32_t>(var.data, count); break;
    case MAT_C_INT64: column.values = to_doubles<std::int64_t>(var.data, count); break;
    case MAT_C_UINT64: column.values = to_doubles<std::uint64_t>(var.data, count); break;
    case MAT_C_CHAR: column.unusable = "text, not numbers"; break;
    case MAT_C_SPARSE: column.unusable = "a sparse matrix"; break;
    case MAT_C_CELL: column.unusable = "a cell array"; break;
    default: column.unusable = "not a numeric vector"; break;
  }
  for (std::size_t i = 0; i < column.values.size() && column.unusable.empty(); ++i)
    if (!std::isfinite(column.values[i])) column.unusable = fmt::format("element {} is not finite", i);
  return column;
}

/// A MAT v7.3 file is an HDF5 file, which matio reads with the HDF5 library: like every HDF5 input it
/// must hold its data itself (hdf5_self_contained.hpp), checked before matio opens any object of it.
void check_mat_v73_self_contained(const std::filesystem::path& file) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (H5Fis_hdf5(file.c_str()) <= 0) return;  // v4 or v5: one file, no links
  const hid_t id = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) return;  // matio reports what it cannot open
  try {
    check_hdf5_self_contained(file, id);
  } catch (...) {
    H5Fclose(id);
    throw;
  }
  H5Fclose(id);
}

}  // namespace

RawLog read_raw_log_mat(const std::filesystem::path& file) {
  check_input_file(file, kMaxDataFileBytes, "a log file");
  check_mat_v73_self_contained(file);
  const MatFile mat(Mat_Open(file.string().c_str(), MAT_ACC_RDONLY));
  if (!mat) throw DataError(file, "", "matio cannot open it as a MAT file", "a MATLAB .mat file (v4, v5 or v7.3)");
  RawLog log;
  log.file = file;
  log.format = LogFormat::Mat;
  while (true) {
    const MatVar var(Mat_VarReadNext(mat.get()));
    if (!var) break;
    const std::string name = var->name ? var->name : "";
    if (var->class_type == MAT_C_STRUCT && var->rank == 2 && var->dims[0] * var->dims[1] == 1) {
      const unsigned fields = Mat_VarGetNumberOfFields(var.get());
      char* const* field_names = Mat_VarGetStructFieldnames(var.get());
      for (unsigned f = 0; f < fields; ++f) {
        const matvar_t* field = Mat_VarGetStructFieldByIndex(var.get(), f, 0);
        const std::string field_name = name + "." + (field_names && field_names[f] ? field_names[f] : std::to_string(f));
        if (field == nullptr) log.columns.push_back({field_name, {}, "an empty field"});
        else log.columns.push_back(column_of(*field, field_name));
      }
      continue;
    }
    if (var->class_type == MAT_C_STRUCT) {
      log.columns.push_back({name, {}, fmt::format("a {} struct array, not a 1 x 1 struct", shape_of(*var))});
      continue;
    }
    log.columns.push_back(column_of(*var, name));
  }
  return log;
}

}  // namespace gpilqg
