#include "gpilqg/core/hdf5_reader.hpp"

#include <algorithm>
#include <functional>
#include <optional>
#include <stdexcept>

#include <H5Cpp.h>

#include "gpilqg/core/dataset_size.hpp"
#include "gpilqg/core/hdf5_self_contained.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "hdf5_common.hpp"

namespace gpilqg {

using hdf5_detail::guarded;

struct Hdf5Reader::Impl {
  H5::H5File file;
  std::uintmax_t file_bytes = 0;  // what declared sizes are checked against (dataset_size.hpp)

  /// Opens the attribute holder at `path`: a group, or a dataset.
  H5::H5Object& object(const std::string& path, H5::Group& group_holder, H5::DataSet& dataset_holder) {
    if (path == "/" || path.empty() || file.childObjType(path) == H5O_TYPE_GROUP) {
      group_holder = file.openGroup(path.empty() ? "/" : path);
      return group_holder;
    }
    dataset_holder = file.openDataSet(path);
    return dataset_holder;
  }
};

namespace {

std::string join(const std::string& group, const std::string& name) {
  return group == "/" ? "/" + name : group + "/" + name;
}

/// Throws DataError at `object` when the dataset or attribute `id` declares more values than the file
/// can hold or than kMaxDatasetValues, before anything is allocated for it.
void check_declared_size(const std::filesystem::path& file, const std::string& object, hid_t id, std::uintmax_t file_bytes) {
  std::optional<std::string> problem;
  try {
    problem = hdf5_size_problem(id, file_bytes);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(file.string() + ": '" + object + "': " + e.what());
  }
  if (problem)
    throw DataError(file, object, *problem, "a dataset that fits the file and at most " + std::to_string(kMaxDatasetValues) + " values");
}

std::string shape_text(const std::vector<std::uint64_t>& dims) {
  if (dims.empty()) return "a scalar";
  std::string text = "(";
  for (std::size_t i = 0; i < dims.size(); ++i) text += (i ? ", " : "") + std::to_string(dims[i]);
  return text + ")";
}

}  // namespace

Hdf5Reader::Hdf5Reader(const std::filesystem::path& file) : impl_(std::make_unique<Impl>()), file_(file) {
  H5::Exception::dontPrint();
  impl_->file_bytes = check_input_file(file, kMaxDataFileBytes, "an HDF5 file");
  guarded(file, "/", "opening", [&] { impl_->file = H5::H5File(file.string(), H5F_ACC_RDONLY); });
  check_hdf5_self_contained(file, impl_->file.getId());
}

Hdf5Reader::~Hdf5Reader() = default;

bool Hdf5Reader::exists(const std::string& path) const {
  if (path.empty() || path == "/") return true;
  // Walk the path so that a missing parent is "absent", not an HDF5 error.
  H5::Group current = impl_->file.openGroup("/");
  std::size_t start = path.front() == '/' ? 1 : 0;
  while (start <= path.size()) {
    const std::size_t slash = path.find('/', start);
    const std::string name = path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (name.empty()) return true;
    if (!current.nameExists(name)) return false;
    if (slash == std::string::npos) return true;
    if (current.childObjType(name) != H5O_TYPE_GROUP) return false;
    current = current.openGroup(name);
    start = slash + 1;
  }
  return true;
}

std::vector<std::string> Hdf5Reader::datasets(const std::string& group) const {
  std::vector<std::string> out;
  const std::function<void(const std::string&)> walk = [&](const std::string& path) {
    const H5::Group g = impl_->file.openGroup(path);
    std::vector<std::string> names;
    for (hsize_t i = 0; i < g.getNumObjs(); ++i) names.push_back(g.getObjnameByIdx(i));
    std::sort(names.begin(), names.end());
    for (const auto& name : names) {
      H5L_info_t info;
      // Soft links are aliases of objects listed elsewhere: not followed.
      if (H5Lget_info(g.getId(), name.c_str(), &info, H5P_DEFAULT) >= 0 && info.type == H5L_TYPE_SOFT) continue;
      const std::string child = join(path, name);
      if (g.childObjType(name) == H5O_TYPE_GROUP) walk(child);
      else if (g.childObjType(name) == H5O_TYPE_DATASET) out.push_back(child);
    }
  };
  guarded(file_, group, "listing group", [&] { walk(group.empty() ? "/" : group); });
  return out;
}

std::optional<std::string> Hdf5Reader::soft_link_target(const std::string& path) const {
  const std::size_t slash = path.find_last_of('/');
  const std::string parent = slash == std::string::npos || slash == 0 ? "/" : path.substr(0, slash);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  if (name.empty() || !exists(parent)) return std::nullopt;
  return guarded(file_, path, "reading link", [&]() -> std::optional<std::string> {
    if (parent != "/" && impl_->file.childObjType(parent) != H5O_TYPE_GROUP) return std::nullopt;
    const H5::Group g = impl_->file.openGroup(parent);
    if (!g.nameExists(name)) return std::nullopt;
    H5L_info_t info;
    if (H5Lget_info(g.getId(), name.c_str(), &info, H5P_DEFAULT) < 0 || info.type != H5L_TYPE_SOFT) return std::nullopt;
    std::string target(info.u.val_size, '\0');
    if (H5Lget_val(g.getId(), name.c_str(), target.data(), target.size(), H5P_DEFAULT) < 0)
      throw std::runtime_error(file_.string() + ": the soft link '" + path + "' cannot be read");
    target.resize(target.find('\0') == std::string::npos ? target.size() : target.find('\0'));
    return target;
  });
}

std::vector<std::uint64_t> Hdf5Reader::shape(const std::string& path) const {
  return guarded(file_, path, "reading the shape of dataset", [&] {
    const H5::DataSpace space = impl_->file.openDataSet(path).getSpace();
    std::vector<hsize_t> dims(static_cast<std::size_t>(space.getSimpleExtentNdims()));
    if (!dims.empty()) space.getSimpleExtentDims(dims.data());
    return std::vector<std::uint64_t>(dims.begin(), dims.end());
  });
}

std::vector<double> Hdf5Reader::read_array(const std::string& path) const {
  return guarded(file_, path, "reading dataset", [&] {
    const H5::DataSet set = impl_->file.openDataSet(path);
    if (set.getTypeClass() != H5T_FLOAT && set.getTypeClass() != H5T_INTEGER)
      throw std::runtime_error(file_.string() + ": dataset '" + path + "' is not numeric");
    check_declared_size(file_, path, set.getId(), impl_->file_bytes);
    const auto count = static_cast<std::size_t>(set.getSpace().getSimpleExtentNpoints());
    std::vector<double> values(count);
    if (count > 0) set.read(values.data(), H5::PredType::NATIVE_DOUBLE);
    return values;
  });
}

Matrix Hdf5Reader::read_matrix(const std::string& path) const {
  const auto dims = shape(path);
  if (dims.size() != 1 && dims.size() != 2)
    throw std::runtime_error(file_.string() + ": dataset '" + path + "' has shape " + shape_text(dims) +
                             "; expected a matrix (2-D)");
  const std::vector<double> values = read_array(path);
  const auto rows = static_cast<Eigen::Index>(dims[0]);
  const auto cols = dims.size() == 2 ? static_cast<Eigen::Index>(dims[1]) : Eigen::Index{1};
  return Eigen::Map<const RowMajorMatrix>(values.data(), rows, cols);
}

Vector Hdf5Reader::read_vector(const std::string& path) const {
  const auto dims = shape(path);
  if (dims.size() > 1)
    throw std::runtime_error(file_.string() + ": dataset '" + path + "' has shape " + shape_text(dims) +
                             "; expected a vector (1-D)");
  const std::vector<double> values = read_array(path);
  return Eigen::Map<const Vector>(values.data(), static_cast<Eigen::Index>(values.size()));
}

double Hdf5Reader::read_scalar(const std::string& path) const {
  const std::vector<double> values = read_array(path);
  if (values.size() != 1)
    throw std::runtime_error(file_.string() + ": dataset '" + path + "' has shape " + shape_text(shape(path)) +
                             "; expected one value");
  return values.front();
}

bool Hdf5Reader::has_attribute(const std::string& object, const std::string& name) const {
  return guarded(file_, object, "opening", [&] {
    H5::Group g;
    H5::DataSet d;
    return impl_->object(object, g, d).attrExists(name);
  });
}

std::vector<std::string> Hdf5Reader::attributes(const std::string& object) const {
  return guarded(file_, object, "listing the attributes of", [&] {
    H5::Group g;
    H5::DataSet d;
    const H5::H5Object& holder = impl_->object(object, g, d);
    std::vector<std::string> names;
    for (int i = 0; i < holder.getNumAttrs(); ++i) names.push_back(holder.openAttribute(static_cast<unsigned>(i)).getName());
    std::sort(names.begin(), names.end());
    return names;
  });
}

std::string Hdf5Reader::string_attribute(const std::string& object, const std::string& name) const {
  return guarded(file_, object + "@" + name, "reading attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    const H5::Attribute a = impl_->object(object, g, d).openAttribute(name);
    if (a.getTypeClass() != H5T_STRING)
      throw std::runtime_error(file_.string() + ": attribute '" + object + "@" + name + "' is not a string");
    check_declared_size(file_, object + "@" + name, a.getId(), impl_->file_bytes);
    std::string value;
    a.read(a.getStrType(), value);
    return value;
  });
}

double Hdf5Reader::number_attribute(const std::string& object, const std::string& name) const {
  return guarded(file_, object + "@" + name, "reading attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    const H5::Attribute a = impl_->object(object, g, d).openAttribute(name);
    if ((a.getTypeClass() != H5T_FLOAT && a.getTypeClass() != H5T_INTEGER) || a.getSpace().getSimpleExtentNpoints() != 1)
      throw std::runtime_error(file_.string() + ": attribute '" + object + "@" + name + "' is not one number");
    double value = 0.0;
    a.read(H5::PredType::NATIVE_DOUBLE, &value);
    return value;
  });
}

std::vector<double> Hdf5Reader::number_list_attribute(const std::string& object, const std::string& name) const {
  return guarded(file_, object + "@" + name, "reading attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    const H5::Attribute a = impl_->object(object, g, d).openAttribute(name);
    if (a.getTypeClass() != H5T_FLOAT && a.getTypeClass() != H5T_INTEGER)
      throw std::runtime_error(file_.string() + ": attribute '" + object + "@" + name + "' is not numeric");
    check_declared_size(file_, object + "@" + name, a.getId(), impl_->file_bytes);
    std::vector<double> values(static_cast<std::size_t>(a.getSpace().getSimpleExtentNpoints()));
    if (!values.empty()) a.read(H5::PredType::NATIVE_DOUBLE, values.data());
    return values;
  });
}

std::vector<std::string> Hdf5Reader::string_list_attribute(const std::string& object, const std::string& name) const {
  return guarded(file_, object + "@" + name, "reading attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    const H5::Attribute a = impl_->object(object, g, d).openAttribute(name);
    const H5::StrType type = a.getStrType();
    if (!type.isVariableStr())
      throw std::runtime_error(file_.string() + ": attribute '" + object + "@" + name +
                               "' is not a list of variable-length strings");
    check_declared_size(file_, object + "@" + name, a.getId(), impl_->file_bytes);
    const auto count = static_cast<std::size_t>(a.getSpace().getSimpleExtentNpoints());
    std::vector<char*> raw(count, nullptr);
    if (count > 0) a.read(type, raw.data());
    std::vector<std::string> values(raw.begin(), raw.end());
    if (count > 0) H5Dvlen_reclaim(type.getId(), a.getSpace().getId(), H5P_DEFAULT, raw.data());
    return values;
  });
}

}  // namespace gpilqg
