/// HDF5 files whose objects all live in the file itself (hdf5_self_contained.hpp).

#include "gpilqg/core/hdf5_self_contained.hpp"

#include <hdf5.h>

#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "gpilqg/core/measurements.hpp"
#include "hdf5_handle.hpp"

namespace gpilqg {

static_assert(std::is_same_v<hid_t, std::int64_t>, "hdf5_self_contained.hpp passes HDF5 identifiers as std::int64_t");

namespace {

/// Names from the file as messages show them: at most 200 bytes, a longer one cut with "...".
std::string shown(std::string name) {
  constexpr std::size_t kMaxShown = 200;
  if (name.size() > kMaxShown) name = name.substr(0, kMaxShown) + "...";
  return name;
}

/// A string that an HDF5 "get name" call writes: asked for its length first, then filled.
template <class Get>
std::string hdf5_string(Get&& get) {
  const auto length = get(nullptr, 0);
  if (length <= 0) return "";
  std::vector<char> text(static_cast<std::size_t>(length) + 1, '\0');
  get(text.data(), text.size());
  return std::string(text.data());
}

/// The target of the external link `name` below `group`: "<file>:<object>".
std::string external_link_target(hid_t group, const char* name, std::size_t size) {
  std::vector<char> value(size + 1, '\0');
  const char* file = nullptr;
  const char* object = nullptr;
  unsigned flags = 0;
  if (H5Lget_val(group, name, value.data(), value.size(), H5P_DEFAULT) < 0 ||
      H5Lunpack_elink_val(value.data(), size, &flags, &file, &object) < 0 || file == nullptr || object == nullptr)
    return "another file";
  return shown(file) + ":" + shown(object);
}

/// Why the dataset `dataset` refers to data outside the file, or an empty string.
std::string dataset_problem(hid_t dataset) {
  const Hdf5Handle plist(H5Dget_create_plist(dataset));
  if (!plist.valid()) throw std::runtime_error("the HDF5 library cannot tell where a dataset's values are stored");
  if (H5Pget_layout(plist.get()) == H5D_VIRTUAL) {
    size_t sources = 0;
    H5Pget_virtual_count(plist.get(), &sources);
    if (sources == 0) return "is a virtual dataset (its values are mapped from other datasets)";
    const std::string file =
        hdf5_string([&](char* text, std::size_t size) { return H5Pget_virtual_filename(plist.get(), 0, text, size); });
    const std::string object =
        hdf5_string([&](char* text, std::size_t size) { return H5Pget_virtual_dsetname(plist.get(), 0, text, size); });
    return "is a virtual dataset mapping the values of " + shown(file) + ":" + shown(object);
  }
  const int external = H5Pget_external_count(plist.get());
  if (external < 0) throw std::runtime_error("the HDF5 library cannot read a dataset's list of external files");
  if (external > 0) {
    char name[256] = "";
    off_t offset = 0;
    hsize_t bytes = 0;
    H5Pget_external(plist.get(), 0, sizeof name, name, &offset, &bytes);
    name[sizeof name - 1] = '\0';
    return "keeps its values in the external file " + shown(name) + " (external raw storage)";
  }
  return "";
}

struct Visit {
  std::optional<Hdf5OutsideReference> found;
  std::string failure;  ///< set when an object cannot be inspected
};

herr_t visit_link(hid_t group, const char* name, const H5L_info_t* info, void* data) {
  auto& visit = *static_cast<Visit*>(data);
  const std::string object = "/" + shown(name);
  switch (info->type) {
    case H5L_TYPE_SOFT:
      return 0;  // resolves inside the file
    case H5L_TYPE_EXTERNAL:
      visit.found = Hdf5OutsideReference{object, "is an external link to " + external_link_target(group, name, info->u.val_size)};
      return 1;
    case H5L_TYPE_HARD:
      break;
    default:
      visit.found = Hdf5OutsideReference{object, "is a user-defined link (class " + std::to_string(info->type) +
                                                     "), which may resolve outside the file"};
      return 1;
  }
  const Hdf5Handle opened(H5Oopen(group, name, H5P_DEFAULT));
  if (!opened.valid()) {
    visit.failure = object + ": the HDF5 library cannot open it";
    return -1;
  }
  if (H5Iget_type(opened.get()) != H5I_DATASET) return 0;
  try {
    std::string problem = dataset_problem(opened.get());
    if (problem.empty()) return 0;
    visit.found = Hdf5OutsideReference{object, std::move(problem)};
    return 1;
  } catch (const std::runtime_error& e) {
    visit.failure = object + ": " + e.what();
    return -1;
  }
}

}  // namespace

std::optional<Hdf5OutsideReference> hdf5_outside_reference(std::int64_t file_id) {
  Visit visit;
  const herr_t status = H5Lvisit(file_id, H5_INDEX_NAME, H5_ITER_INC, visit_link, &visit);
  if (visit.found) return visit.found;
  if (status < 0)
    throw std::runtime_error(visit.failure.empty() ? "the HDF5 library cannot list the objects of the file" : visit.failure);
  return std::nullopt;
}

void check_hdf5_self_contained(const std::filesystem::path& file, std::int64_t file_id) {
  std::optional<Hdf5OutsideReference> outside;
  try {
    outside = hdf5_outside_reference(file_id);
  } catch (const std::runtime_error& e) {
    throw DataError(file, "", e.what(), "a readable HDF5 file");
  }
  if (outside) throw DataError(file, outside->object, outside->problem, "data stored in the file itself");
}

}  // namespace gpilqg
