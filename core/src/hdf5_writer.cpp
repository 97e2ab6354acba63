#include "gpilqg/core/hdf5_writer.hpp"

#include <exception>
#include <stdexcept>

#include <H5Cpp.h>

#include "gpilqg/core/hdf5_memory_file.hpp"
#include "hdf5_common.hpp"

namespace gpilqg {

struct Hdf5Writer::Impl {
  H5::H5File file;  ///< in memory until close() (hdf5_memory_file.hpp)
  int uncaught_exceptions = std::uncaught_exceptions();

  /// The group at `path` ("/" or "/a/b"), created with its parents when missing.
  H5::Group group(const std::string& path) {
    H5::Group current = file.openGroup("/");
    std::size_t start = 0;
    while (start < path.size()) {
      const std::size_t slash = path.find('/', start);
      const std::size_t end = slash == std::string::npos ? path.size() : slash;
      const std::string name = path.substr(start, end - start);
      if (!name.empty()) current = current.nameExists(name) ? current.openGroup(name) : current.createGroup(name);
      start = end + 1;
    }
    return current;
  }

  /// The parent group of `path` and the last name in it.
  std::pair<H5::Group, std::string> parent_of(const std::string& path) {
    const std::size_t slash = path.find_last_of('/');
    if (slash == std::string::npos) return {group("/"), path};
    return {group(path.substr(0, slash)), path.substr(slash + 1)};
  }

  H5::H5Object& object(const std::string& path, H5::Group& group_holder, H5::DataSet& dataset_holder) {
    auto [parent, name] = parent_of(path);
    if (name.empty() || !parent.nameExists(name) || parent.childObjType(name) == H5O_TYPE_GROUP) {
      group_holder = group(path);
      return group_holder;
    }
    dataset_holder = parent.openDataSet(name);
    return dataset_holder;
  }

  void dataset(const std::string& path, const std::vector<hsize_t>& dims, const double* data) {
    auto [parent, name] = parent_of(path);
    const H5::DataSpace space = dims.empty() ? H5::DataSpace(H5S_SCALAR)
                                             : H5::DataSpace(static_cast<int>(dims.size()), dims.data());
    const H5::DataSet set = parent.createDataSet(name, H5::PredType::IEEE_F64LE, space);
    hsize_t count = 1;
    for (const hsize_t d : dims) count *= d;
    if (count > 0) set.write(data, H5::PredType::NATIVE_DOUBLE);
  }
};

using hdf5_detail::guarded;

Hdf5Writer::Hdf5Writer(const std::filesystem::path& file) : impl_(std::make_unique<Impl>()), file_(file) {
  guarded(file, "/", "creating", [&] {
    H5::Exception::dontPrint();
    impl_->file = create_hdf5_in_memory(file);
  });
}

Hdf5Writer::~Hdf5Writer() {
  // Like std::ofstream, a writer that was not closed writes its file now, unless it is being
  // destroyed by an exception (then the half-built file is dropped); errors cannot be reported here,
  // which is why every writer of the project calls close().
  if (!impl_ || std::uncaught_exceptions() > impl_->uncaught_exceptions) return;
  try {
    std::error_code ignored;
    std::filesystem::remove(file_, ignored);
    save_hdf5_image(impl_->file, file_);
  } catch (...) {
  }
}

void Hdf5Writer::close() {
  if (!impl_) throw std::runtime_error(file_.string() + ": already closed");
  const std::unique_ptr<Impl> impl = std::move(impl_);
  std::error_code ignored;
  std::filesystem::remove(file_, ignored);  // "creates or truncates"
  guarded(file_, "/", "closing", [&] { save_hdf5_image(impl->file, file_); });
}

void Hdf5Writer::write_matrix(const std::string& path, const MatrixCRef& values) {
  const RowMajorMatrix rows = values;
  guarded(file_, path, "writing dataset", [&] {
    impl_->dataset(path, {static_cast<hsize_t>(values.rows()), static_cast<hsize_t>(values.cols())}, rows.data());
  });
}

void Hdf5Writer::write_vector(const std::string& path, const VectorCRef& values) {
  const Vector copy = values;
  guarded(file_, path, "writing dataset", [&] { impl_->dataset(path, {static_cast<hsize_t>(copy.size())}, copy.data()); });
}

void Hdf5Writer::write_vector(const std::string& path, const std::vector<double>& values) {
  guarded(file_, path, "writing dataset", [&] { impl_->dataset(path, {values.size()}, values.data()); });
}

void Hdf5Writer::write_vector(const std::string& path, const std::vector<int>& values) {
  write_vector(path, std::vector<double>(values.begin(), values.end()));
}

void Hdf5Writer::write_scalar(const std::string& path, double value) {
  guarded(file_, path, "writing dataset", [&] { impl_->dataset(path, {}, &value); });
}

void Hdf5Writer::write_array(const std::string& path, const std::vector<std::uint64_t>& dims, const std::vector<double>& values) {
  std::uint64_t count = 1;
  for (const auto d : dims) count *= d;
  if (count != values.size())
    throw std::invalid_argument(file_.string() + ": dataset '" + path + "': " + std::to_string(values.size()) +
                                " values for a shape of " + std::to_string(count));
  const std::vector<hsize_t> shape(dims.begin(), dims.end());
  guarded(file_, path, "writing dataset", [&] { impl_->dataset(path, shape, values.data()); });
}

void Hdf5Writer::attribute(const std::string& object, const std::string& name, const std::string& value) {
  guarded(file_, object + "@" + name, "writing attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    const H5::StrType type = hdf5_detail::utf8_string_type();
    const char* data[1] = {value.c_str()};
    impl_->object(object, g, d).createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, data);
  });
}

void Hdf5Writer::attribute(const std::string& object, const std::string& name, double value) {
  guarded(file_, object + "@" + name, "writing attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    impl_->object(object, g, d)
        .createAttribute(name, H5::PredType::IEEE_F64LE, H5::DataSpace(H5S_SCALAR))
        .write(H5::PredType::NATIVE_DOUBLE, &value);
  });
}

void Hdf5Writer::attribute(const std::string& object, const std::string& name, std::int64_t value) {
  guarded(file_, object + "@" + name, "writing attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    impl_->object(object, g, d)
        .createAttribute(name, H5::PredType::STD_I64LE, H5::DataSpace(H5S_SCALAR))
        .write(H5::PredType::NATIVE_INT64, &value);
  });
}

void Hdf5Writer::attribute(const std::string& object, const std::string& name, const std::vector<std::string>& values) {
  guarded(file_, object + "@" + name, "writing attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    const H5::StrType type = hdf5_detail::utf8_string_type();
    std::vector<const char*> data;
    for (const auto& v : values) data.push_back(v.c_str());
    const hsize_t dims[1] = {values.size()};
    H5::Attribute a = impl_->object(object, g, d).createAttribute(name, type, H5::DataSpace(1, dims));
    if (!values.empty()) a.write(type, data.data());  // an empty list has nothing to write
  });
}

void Hdf5Writer::attribute(const std::string& object, const std::string& name, const std::vector<double>& values) {
  guarded(file_, object + "@" + name, "writing attribute", [&] {
    H5::Group g;
    H5::DataSet d;
    const hsize_t dims[1] = {values.size()};
    H5::Attribute a = impl_->object(object, g, d).createAttribute(name, H5::PredType::IEEE_F64LE, H5::DataSpace(1, dims));
    if (!values.empty()) a.write(H5::PredType::NATIVE_DOUBLE, values.data());
  });
}

void Hdf5Writer::link(const std::string& path, const std::string& target) {
  guarded(file_, path, "linking", [&] {
    auto [parent, name] = impl_->parent_of(path);
    parent.link(H5L_TYPE_SOFT, target, name);
  });
}

}  // namespace gpilqg
