/// HDF5 measurement files (docs/formats.md#measurement-data-csv-and-hdf5):
///
///   / (attributes: system (string), state_names, control_names (1-D string arrays))
///   /episodes/<k>/t   (T)      float64, strictly increasing, constant step
///   /episodes/<k>/x   (T x n)  float64, the measured states in the order of state_names
///   /episodes/<k>/u   (T x m)  float64, the applied controls in the order of control_names
///
/// A system without controls (m = 0, a passive system): control_names may be absent or empty and each
/// u absent or of shape (T x 0); the writer writes an empty control_names and u of shape (T x 0).
///
/// Optional root attribute estimated_states (1-D string array): the states that were estimated from
/// others rather than measured (MeasurementSet::estimated_states), each a name of state_names, once.
/// Absent means every state was measured; the writer writes it only when some state was estimated.
///
/// The reader accepts variable-length and fixed-length strings (null- or space-padded) and any
/// floating-point storage type; episodes come back ordered by k. Other objects (extra attributes,
/// groups or datasets) are ignored. Every failure, including one inside the HDF5 library, is a
/// DataError naming the dataset or attribute. The writer uses variable-length UTF-8 strings.

#include <H5Cpp.h>
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>

#include "gpilqg/core/dataset_size.hpp"
#include "gpilqg/core/hdf5_memory_file.hpp"
#include "gpilqg/core/hdf5_self_contained.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "measurements_internal.hpp"
#include "name_list.hpp"

namespace gpilqg {

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// "['a', 'b']": the names of the system, all of them.
std::string quoted_list(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "'" : ", '") + name + "'";
  return "[" + text + "]";
}

/// "['a', 'b', ... and N more]": names found in the file, bounded whatever it holds (name_list.hpp).
std::string found_list(const std::vector<std::string>& names) { return "[" + name_list::quoted_list(names) + "]"; }

std::string attribute_location(const std::string& name) { return "attribute '" + name + "'"; }

/// Runs `action` and turns an HDF5 library failure into a DataError at `location`.
template <class Action>
auto guarded(const std::filesystem::path& file, const std::string& location, const std::string& what,
             const std::string& expected, Action&& action) -> decltype(action()) {
  try {
    return action();
  } catch (const H5::Exception& e) {
    std::string detail = e.getDetailMsg();
    if (detail.empty()) detail = e.getFuncName();
    throw DataError(file, location, what + " failed (HDF5: " + detail + ")", expected);
  }
}

/// Decimal digits only, as the name of /episodes/<k>; nullopt otherwise.
std::optional<long> parse_episode_name(const std::string& name) {
  if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  long value = 0;
  const auto [end, error] = std::from_chars(name.data(), name.data() + name.size(), value);
  if (error != std::errc() || end != name.data() + name.size()) return std::nullopt;
  return value;
}

class MeasurementsHdf5Reader {
 public:
  MeasurementsHdf5Reader(const std::filesystem::path& file, const SystemSignature& system) : file_(file), system_(system) {}

  MeasurementSet read() {
    H5::Exception::dontPrint();
    open();
    return guarded(file_, "/", "reading the file", "a valid HDF5 measurement file", [&] {
      const H5::Group root = h5_.openGroup("/");
      check_attributes(root);
      MeasurementSet set;
      set.system = system_;
      set.estimated_states = estimated_states(root);
      const auto names = guarded(file_, "/episodes", "listing the episodes", "a readable group /episodes",
                                 [&] { return episode_names(); });
      for (const auto& [id, name] : names) set.episodes.push_back(read_episode(id, name));
      return set;
    });
  }

 private:
  void open() {
    file_size_ = check_input_file(file_, kMaxDataFileBytes, "a measurement file");
    const bool is_hdf5 = guarded(file_, "", "opening the file", "a readable HDF5 file",
                                 [&] { return H5::H5File::isHdf5(file_.c_str()); });
    if (!is_hdf5) throw DataError(file_, "", "not an HDF5 file", "an HDF5 file (a CSV file must end in .csv)");
    h5_ = guarded(file_, "", "opening the file", "a readable HDF5 file",
                  [&] { return H5::H5File(file_.c_str(), H5F_ACC_RDONLY); });
    check_hdf5_self_contained(file_, h5_.getId());
  }

  /// Refuses a dataset or attribute that declares more values than the file can hold or than
  /// kMaxDatasetValues, before anything is allocated for it.
  void check_declared_size(hid_t object, const std::string& location, const std::string& expected) const {
    std::optional<std::string> problem;
    try {
      problem = hdf5_size_problem(object, file_size_);
    } catch (const std::runtime_error& e) {
      problem = e.what();
    }
    if (problem) throw DataError(file_, location, *problem, expected);
  }

  /// The strings of an attribute (scalar when `scalar`, else a 1-D array), variable- or fixed-length.
  std::vector<std::string> read_strings(const H5::Group& root, const std::string& name, bool scalar,
                                        const std::string& expected) const {
    const std::string location = attribute_location(name);
    if (!root.attrExists(name)) throw DataError(file_, location, "missing", expected);
    return guarded(file_, location, "reading the attribute", expected, [&] {
      const H5::Attribute attribute = root.openAttribute(name);
      if (attribute.getTypeClass() != H5T_STRING)
        throw DataError(file_, location, "is not a string attribute", expected);
      const H5::DataSpace space = attribute.getSpace();
      const int rank = space.getSimpleExtentNdims();
      if (scalar && rank != 0)
        throw DataError(file_, location, fmt::format("is an array of rank {}, not a single string", rank),
                        expected);
      if (!scalar && rank != 1)
        throw DataError(file_, location, fmt::format("has rank {}, not a 1-D array of strings", rank),
                        expected);
      check_declared_size(attribute.getId(), location, expected);
      const auto count = static_cast<std::size_t>(space.getSimpleExtentNpoints());
      if (scalar && count != 1)
        throw DataError(file_, location, "holds no value (an empty dataspace), not a single string", expected);
      const H5::StrType type = attribute.getStrType();
      std::vector<std::string> strings;
      if (count == 0) return strings;  // an empty array (the control names of a passive system)
      if (type.isVariableStr()) {
        std::vector<char*> buffer(count, nullptr);
        attribute.read(type, buffer.data());
        for (const char* s : buffer) strings.emplace_back(s == nullptr ? "" : s);
        H5::DataSet::vlenReclaim(buffer.data(), type, space);
      } else {
        const std::size_t size = type.getSize();
        std::vector<char> buffer(count * size);
        attribute.read(type, buffer.data());
        const bool space_padded = type.getStrpad() == H5T_STR_SPACEPAD;
        for (std::size_t i = 0; i < count; ++i) {
          std::string s(buffer.data() + i * size, size);
          if (space_padded)
            s.erase(s.find_last_not_of(' ') + 1);
          else if (const auto nul = s.find('\0'); nul != std::string::npos)
            s.erase(nul);
          strings.push_back(std::move(s));
        }
      }
      return strings;
    });
  }

  void check_attributes(const H5::Group& root) const {
    const std::string system_expected = "the system name '" + system_.name + "'";
    const std::string found = read_strings(root, "system", true, system_expected).front();
    if (found != system_.name)
      throw DataError(file_, attribute_location("system"), "the file holds data of system '" + found + "'",
                      "'" + system_.name + "' (the --system given)");
    check_names(root, "state_names", names_of(system_.states), "state");
    // A system without controls (a passive system): control_names may be absent, or an empty array.
    if (!system_.controls.empty() || root.attrExists("control_names"))
      check_names(root, "control_names", names_of(system_.controls), "control");
  }

  /// The optional attribute estimated_states: empty when absent, else distinct state names.
  std::vector<std::string> estimated_states(const H5::Group& root) const {
    const std::string name = "estimated_states";
    if (!root.attrExists(name)) return {};
    const std::string expected = fmt::format(
        "a 1-D array of the states estimated from others (e.g. by gpilqg data import), each one of the states of "
        "system '{}' once: {}",
        system_.name, quoted_list(names_of(system_.states)));
    const std::vector<std::string> found = read_strings(root, name, false, expected);
    std::vector<std::string> seen;
    for (const std::string& state : found) {
      if (index_of(system_.states, state) < 0)
        throw DataError(file_, attribute_location(name),
                        fmt::format("names {}, which is not a state of system '{}'", name_list::quoted(state),
                                    system_.name),
                        expected);
      if (std::find(seen.begin(), seen.end(), state) != seen.end())
        throw DataError(file_, attribute_location(name), fmt::format("lists {} twice", name_list::quoted(state)), expected);
      seen.push_back(state);
    }
    return found;
  }

  void check_names(const H5::Group& root, const std::string& attribute,
                   const std::vector<std::string>& expected, const std::string& kind) const {
    const std::string expectation =
        fmt::format("the {} names of system '{}' in order: {}", kind, system_.name, quoted_list(expected));
    const std::vector<std::string> found = read_strings(root, attribute, false, expectation);
    if (found == expected) return;
    auto sorted_found = found, sorted_expected = expected;
    std::sort(sorted_found.begin(), sorted_found.end());
    std::sort(sorted_expected.begin(), sorted_expected.end());
    const std::string problem = sorted_found == sorted_expected
                                    ? "has the right names in a different order: " + quoted_list(found)
                                    : "is " + found_list(found);
    throw DataError(file_, attribute_location(attribute), problem, expectation);
  }

  /// The episode groups under /episodes as (k, name), ordered by k.
  std::vector<std::pair<long, std::string>> episode_names() const {
    const std::string expected =
        "a group /episodes holding one group /episodes/<k> per episode (k = 0, 1, ...)";
    if (!h5_.nameExists("episodes")) throw DataError(file_, "/episodes", "missing", expected);
    if (h5_.childObjType("episodes") != H5O_TYPE_GROUP)
      throw DataError(file_, "/episodes", "is not a group", expected);
    const H5::Group episodes = h5_.openGroup("episodes");
    std::vector<std::pair<long, std::string>> names;
    std::map<long, std::string> seen_ids;  // k -> the first group name of episode k
    for (hsize_t i = 0; i < episodes.getNumObjs(); ++i) {
      const std::string name = episodes.getObjnameByIdx(i);
      const std::string location = "/episodes/" + name;
      const auto id = parse_episode_name(name);
      if (!id) throw DataError(file_, location, "the name is not a non-negative integer", expected);
      if (episodes.childObjType(name) != H5O_TYPE_GROUP)
        throw DataError(file_, location, "is not a group", expected);
      if (const auto [seen, added] = seen_ids.emplace(*id, name); !added)
        throw DataError(file_, location,
                        "names episode " + std::to_string(*id) + " like /episodes/" + seen->second,
                        "one group per episode number");
      names.emplace_back(*id, name);
    }
    if (names.empty()) throw DataError(file_, "/episodes", "holds no episodes", expected);
    std::sort(names.begin(), names.end());
    return names;
  }

  /// Reads /episodes/<name>/<dataset> as a float64 array of the given shape. `rows` < 0 accepts any
  /// length; `cols` < 0 means a 1-D dataset.
  RowMajor read_dataset(const H5::Group& group, const std::string& prefix, const std::string& dataset,
                        Eigen::Index rows, Eigen::Index cols, const std::string& expected) const {
    const std::string location = prefix + "/" + dataset;
    if (!group.nameExists(dataset)) throw DataError(file_, location, "missing", expected);
    if (group.childObjType(dataset) != H5O_TYPE_DATASET)
      throw DataError(file_, location, "is not a dataset", expected);
    return guarded(file_, location, "reading the dataset", expected, [&] {
      const H5::DataSet data = group.openDataSet(dataset);
      if (data.getTypeClass() != H5T_FLOAT)
        throw DataError(file_, location, "does not hold floating-point numbers", expected);
      const H5::DataSpace space = data.getSpace();
      const int rank = space.getSimpleExtentNdims();
      hsize_t dims[2] = {0, 0};
      if (rank == 1 || rank == 2) space.getSimpleExtentDims(dims);
      const int expected_rank = cols < 0 ? 1 : 2;
      const auto found_rows = static_cast<Eigen::Index>(dims[0]);
      const auto found_cols = static_cast<Eigen::Index>(rank == 2 ? dims[1] : 1);
      if (rank != expected_rank || (rows >= 0 && found_rows != rows) || (cols >= 0 && found_cols != cols)) {
        std::string shape = rank == 0 ? "a scalar" : fmt::format("shape ({})", dims[0]);
        if (rank == 2) shape = fmt::format("shape ({} x {})", dims[0], dims[1]);
        if (rank > 2) shape = fmt::format("rank {}", rank);
        throw DataError(file_, location, "has " + shape, expected);
      }
      // A damaged file can declare any extent: refused before the allocation (dataset_size.hpp).
      check_declared_size(data.getId(), location, expected);
      RowMajor values(found_rows, cols < 0 ? 1 : cols);
      if (values.size() > 0) data.read(values.data(), H5::PredType::NATIVE_DOUBLE);
      return values;
    });
  }

  void check_finite(const RowMajor& values, const std::string& location,
                    const std::vector<Quantity>* quantities, const std::string& kind) const {
    for (Eigen::Index i = 0; i < values.rows(); ++i)
      for (Eigen::Index j = 0; j < values.cols(); ++j)
        if (!std::isfinite(values(i, j))) {
          const std::string where = quantities == nullptr
                                        ? fmt::format("entry [{}]", i)
                                        : fmt::format("entry [{}, {}] (sample {}, {} '{}')", i, j, i, kind,
                                                      (*quantities)[static_cast<std::size_t>(j)].name);
          throw DataError(file_, location, fmt::format("{} is {}", where, values(i, j)), "finite values only");
        }
  }

  Episode read_episode(long id, const std::string& name) const {
    const std::string prefix = "/episodes/" + name;
    const H5::Group group =
        guarded(file_, prefix, "opening the group", "a readable group", [&] { return h5_.openGroup(prefix); });
    const auto n = static_cast<Eigen::Index>(system_.states.size());
    const auto m = static_cast<Eigen::Index>(system_.controls.size());

    const RowMajor t = read_dataset(group, prefix, "t", -1, -1, "a 1-D float64 dataset of the T sample times");
    const Eigen::Index T = t.rows();
    const RowMajor x = read_dataset(group, prefix, "x", T, n,
                                    fmt::format("shape ({} x {}): T = {} samples as in {}/t, n = {} states {}",
                                                T, n, T, prefix, n, quoted_list(names_of(system_.states))));
    // A system without controls (a passive system): u may be absent, or of shape (T x 0).
    const RowMajor u =
        m == 0 && !group.nameExists("u")
            ? RowMajor(T, 0)
            : read_dataset(group, prefix, "u", T, m,
                           fmt::format("shape ({} x {}): T = {} samples as in {}/t, m = {} controls {}", T, m, T,
                                       prefix, m, quoted_list(names_of(system_.controls))));
    check_finite(t, prefix + "/t", nullptr, "");
    check_finite(x, prefix + "/x", &system_.states, "state");
    check_finite(u, prefix + "/u", &system_.controls, "control");

    Episode episode;
    episode.id = id;
    episode.t = t.col(0);
    if (const auto issue = measurements_detail::check_times(episode.t))
      throw DataError(file_, prefix + "/t",
                      T < 2 ? issue->problem : fmt::format("at index {}: {}", issue->index, issue->problem),
                      issue->expected);
    episode.x = x;
    episode.u = u;
    return episode;
  }

  const std::filesystem::path& file_;
  const SystemSignature& system_;
  H5::H5File h5_;
  std::uintmax_t file_size_ = 0;
};

H5::StrType variable_string_type() {
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  return type;
}

void write_string(H5::Group& root, const std::string& name, const std::string& value) {
  const H5::StrType type = variable_string_type();
  const char* data[1] = {value.c_str()};
  root.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, data);
}

void write_strings(H5::Group& root, const std::string& name, const std::vector<std::string>& values) {
  const H5::StrType type = variable_string_type();
  std::vector<const char*> data;
  for (const auto& value : values) data.push_back(value.c_str());
  const hsize_t dims[1] = {values.size()};
  const H5::Attribute attribute = root.createAttribute(name, type, H5::DataSpace(1, dims));
  if (!values.empty()) attribute.write(type, data.data());  // an empty array: nothing to write
}

void write_array(H5::Group& group, const std::string& name, const RowMajor& values, bool one_dimensional) {
  const hsize_t dims[2] = {static_cast<hsize_t>(values.rows()), static_cast<hsize_t>(values.cols())};
  const H5::DataSpace space(one_dimensional ? 1 : 2, dims);
  const H5::DataSet data = group.createDataSet(name, H5::PredType::IEEE_F64LE, space);
  if (values.size() > 0) data.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

}  // namespace

MeasurementSet read_measurements_hdf5(const std::filesystem::path& file, const SystemSignature& system) {
  return MeasurementsHdf5Reader(file, system).read();
}

void write_measurements_hdf5(const std::filesystem::path& file, const MeasurementSet& set) {
  measurements_detail::check_writable(set);
  H5::Exception::dontPrint();
  guarded(file, "", "writing the file", "a set HDF5 can store", [&] {
    write_hdf5_atomically(file, [&](H5::H5File& h5) {
      H5::Group root = h5.openGroup("/");
      write_string(root, "system", set.system.name);
      write_strings(root, "state_names", names_of(set.system.states));
      write_strings(root, "control_names", names_of(set.system.controls));
      if (!set.estimated_states.empty()) write_strings(root, "estimated_states", set.estimated_states);
      H5::Group episodes = h5.createGroup("episodes");
      for (const Episode& e : set.episodes) {
        H5::Group group = episodes.createGroup(std::to_string(e.id));
        write_array(group, "t", e.t, true);
        write_array(group, "x", e.x, false);
        write_array(group, "u", e.u, false);
      }
    });
  });
}

}  // namespace gpilqg
