#include "harnesses.hpp"

#include <H5Cpp.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/run_config.hpp"
#include "gpilqg/experiments/solve_config.hpp"

namespace gpilqg::fuzz {

namespace {

// ---------------------------------------------------------------------------------------------------
// Shared pieces

[[noreturn]] void violated(const std::string& what) { throw FuzzInvariantViolation(what); }

void write_bytes(const std::filesystem::path& file, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw std::runtime_error("fuzz harness: cannot write " + file.string());
}

const SystemSignature& system_named(std::string_view name) {
  static const SystemSignature cartpole = system_signature("cartpole");
  static const SystemSignature quadrotor = system_signature("quadrotor");
  return name == "cartpole" ? cartpole : quadrotor;
}

/// What read_measurements_* promise about a set they return (measurements.hpp).
void check_measurements(const MeasurementSet& set, const SystemSignature& system) {
  if (set.system.name != system.name) violated("the set names another system");
  if (set.episodes.empty()) violated("a set without episodes was accepted");
  const auto n = static_cast<Eigen::Index>(system.states.size());
  const auto m = static_cast<Eigen::Index>(system.controls.size());
  std::vector<long> ids;
  for (const Episode& e : set.episodes) {
    if (e.id < 0) violated("negative episode id " + std::to_string(e.id));
    for (long id : ids)
      if (id == e.id) violated("episode id " + std::to_string(e.id) + " twice");
    ids.push_back(e.id);
    const Eigen::Index T = e.t.size();
    if (T < 2) violated("an episode with fewer than 2 samples was accepted");
    if (e.x.rows() != T || e.x.cols() != n || e.u.rows() != T || e.u.cols() != m)
      violated("episode " + std::to_string(e.id) + " has inconsistent shapes");
    if (!e.t.allFinite() || !e.x.allFinite() || !e.u.allFinite())
      violated("episode " + std::to_string(e.id) + " holds non-finite values");
    const double first = e.t(1) - e.t(0);
    for (Eigen::Index i = 1; i < T; ++i) {
      const double step = e.t(i) - e.t(i - 1);
      if (!(step > 0.0) || !std::isfinite(step))
        violated("episode " + std::to_string(e.id) + ": t not strictly increasing by finite steps");
      if (std::abs(step - first) > 1e-6 * first) violated("episode " + std::to_string(e.id) + ": dt not constant");
    }
  }
}

bool same_bits(const Matrix& a, const Matrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

/// Accepted data must survive both writers and readers bit for bit (README: "CSV -> HDF5 -> CSV is
/// exact to the bit").
void check_round_trip(const MeasurementSet& set, const SystemSignature& system) {
  for (const char* name : {"round_trip.csv", "round_trip.h5"}) {
    const std::filesystem::path file = scratch_dir() / name;
    write_measurements(file, set);
    const MeasurementSet back = read_measurements(file, system);
    if (back.episodes.size() != set.episodes.size()) violated(std::string(name) + ": episode count changed");
    for (std::size_t k = 0; k < set.episodes.size(); ++k) {
      const Episode& a = set.episodes[k];
      const Episode& b = back.episodes[k];
      if (a.id != b.id || !same_bits(a.t, b.t) || !same_bits(a.x, b.x) || !same_bits(a.u, b.u))
        violated(std::string(name) + ": episode " + std::to_string(a.id) + " changed in the round trip");
    }
  }
}

/// Reads `file` with `read`, accepting a DataError that names the file; checks what comes back.
template <class Read>
void read_and_check(const SystemSignature& system, const std::filesystem::path& file, Read&& read) {
  MeasurementSet set;
  try {
    set = read();
  } catch (const DataError& e) {
    if (std::string_view(e.what()).rfind(file.string() + ":", 0) != 0 || e.file() != file)
      violated(std::string("a DataError that does not start with the file name: ") + e.what());
    return;
  }
  check_measurements(set, system);
  check_round_trip(set, system);
}

// ---------------------------------------------------------------------------------------------------
// Bytes -> choices, for the structured HDF5 harness (a small stand-in for libFuzzer's
// FuzzedDataProvider, which GCC builds of the replay test do not have). Past the end: zeros.

class Choices {
 public:
  Choices(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return position_ < size_ ? data_[position_++] : 0; }
  unsigned below(unsigned count) { return byte() % count; }
  bool flag() { return (byte() & 1) != 0; }
  std::string text(std::size_t max_length) {
    const std::size_t length = below(static_cast<unsigned>(max_length) + 1);
    std::string s;
    for (std::size_t i = 0; i < length; ++i) s.push_back(static_cast<char>(byte()));
    return s;
  }
  double number() {
    static constexpr double kPool[] = {0.0, 1.0, -1.0, 0.05, 1e-300, 4.9e-324, 1e300, -0.0, 3.0, 0.1};
    switch (below(8)) {
      case 0: return std::numeric_limits<double>::quiet_NaN();
      case 1: return flag() ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
      case 2: {
        double value = 0.0;
        std::uint8_t bytes[sizeof(double)];
        for (auto& b : bytes) b = byte();
        std::memcpy(&value, bytes, sizeof value);
        return value;
      }
      default: return kPool[below(sizeof kPool / sizeof kPool[0])];
    }
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t position_ = 0;
};

H5::StrType string_type(Choices& c) {
  if (c.flag()) return H5::StrType(H5::PredType::C_S1, H5T_VARIABLE);
  H5::StrType type(H5::PredType::C_S1, 1 + c.below(12));
  static constexpr H5T_str_t kPads[] = {H5T_STR_NULLTERM, H5T_STR_NULLPAD, H5T_STR_SPACEPAD};
  type.setStrpad(kPads[c.below(3)]);
  return type;
}

/// Writes strings with `type` (variable or fixed length; fixed ones are cut or padded).
void write_string_values(H5::Attribute& attribute, const H5::StrType& type, const std::vector<std::string>& values) {
  if (values.empty()) return;
  if (type.isVariableStr()) {
    std::vector<const char*> pointers;
    for (const auto& v : values) pointers.push_back(v.c_str());
    attribute.write(type, pointers.data());
    return;
  }
  const std::size_t width = type.getSize();
  std::vector<char> buffer(values.size() * width, '\0');
  for (std::size_t i = 0; i < values.size(); ++i)
    std::memcpy(buffer.data() + i * width, values[i].data(), std::min(width, values[i].size()));
  attribute.write(type, buffer.data());
}

/// A list of names: the right ones, the right ones shuffled or cut, or made up.
std::vector<std::string> names_choice(Choices& c, const std::vector<std::string>& right) {
  std::vector<std::string> names = right;
  switch (c.below(5)) {
    case 0: return names;
    case 1: if (names.size() > 1) std::swap(names[0], names[names.size() - 1]); return names;
    case 2: if (!names.empty()) names.pop_back(); return names;
    case 3: names.push_back(c.text(6)); return names;
    default: {
      std::vector<std::string> made_up(c.below(6));
      for (auto& name : made_up) name = c.text(8);
      return made_up;
    }
  }
}

/// A root attribute holding `values` in one of many (mostly wrong) forms, or absent.
void write_attribute(Choices& c, H5::Group& root, const std::string& name, std::vector<std::string> values,
                     bool scalar_expected) {
  switch (c.below(8)) {
    case 0: return;  // absent
    case 1: {        // an integer
      const int value = 7;
      root.createAttribute(name, H5::PredType::NATIVE_INT, H5::DataSpace(H5S_SCALAR))
          .write(H5::PredType::NATIVE_INT, &value);
      return;
    }
    case 2: {  // a string attribute with a null dataspace (no value at all)
      root.createAttribute(name, string_type(c), H5::DataSpace(H5S_NULL));
      return;
    }
    case 3: {  // a 2-D array of strings
      const hsize_t dims[2] = {1, static_cast<hsize_t>(std::max<std::size_t>(values.size(), 1))};
      values.resize(dims[1]);
      const H5::StrType type = string_type(c);
      H5::Attribute a = root.createAttribute(name, type, H5::DataSpace(2, dims));
      write_string_values(a, type, values);
      return;
    }
    default: break;
  }
  const H5::StrType type = string_type(c);
  const bool scalar = c.below(4) == 0 ? !scalar_expected : scalar_expected;
  if (scalar) {
    if (values.empty()) values.emplace_back();
    values.resize(1);
    H5::Attribute a = root.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
    write_string_values(a, type, values);
  } else {
    const hsize_t dims[1] = {values.size()};
    H5::Attribute a = root.createAttribute(name, type, H5::DataSpace(1, dims));
    write_string_values(a, type, values);
  }
}

/// A dataset `name` in `group` with a chosen type, rank and shape; `rows` and `cols` are the shape a
/// valid file would have, `times` makes the values a (possibly broken) time axis.
void write_dataset(Choices& c, H5::Group& group, const std::string& name, hsize_t rows, hsize_t cols, bool times) {
  switch (c.below(10)) {
    case 0: return;                                     // absent
    case 1: group.createGroup(name); return;            // a group instead
    case 2: {                                           // strings
      const H5::StrType type(H5::PredType::C_S1, 4);
      const hsize_t dims[1] = {rows};
      group.createDataSet(name, type, H5::DataSpace(1, dims));
      return;
    }
    case 3: group.createDataSet(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(H5S_NULL)); return;
    default: break;
  }
  int rank = cols == 0 ? 1 : 2;
  if (c.below(6) == 0) rank = static_cast<int>(c.below(4));
  hsize_t dims[3] = {rows, cols, 1 + c.below(3)};
  if (c.below(5) == 0) dims[0] = c.below(7);
  if (c.below(5) == 0) dims[1] = c.below(14);
  if (rank == 1 && cols != 0) dims[0] = rows * cols;
  const H5::DataSpace space = rank == 0 ? H5::DataSpace(H5S_SCALAR) : H5::DataSpace(rank, dims);
  static const H5::PredType* kTypes[] = {&H5::PredType::IEEE_F64LE, &H5::PredType::IEEE_F64BE,
                                         &H5::PredType::IEEE_F32LE, &H5::PredType::NATIVE_INT};
  const H5::PredType& type = *kTypes[c.below(5) % 4];
  H5::DSetCreatPropList properties;
  if (rank > 0 && dims[0] > 0 && c.below(4) == 0) {
    properties.setChunk(rank, dims);
    properties.setDeflate(1);
  }
  const H5::DataSet data = group.createDataSet(name, type, space, properties);
  const hssize_t count = space.getSimpleExtentNpoints();
  if (count <= 0) return;
  std::vector<double> values(static_cast<std::size_t>(count));
  const double start = c.number(), step = c.flag() ? 0.05 : c.number();
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (times && c.below(8) != 0)
      values[i] = start + step * static_cast<double>(i);
    else
      values[i] = c.below(4) == 0 ? c.number() : 0.01 * static_cast<double>(c.byte());
  }
  data.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

void write_episode(Choices& c, H5::Group& episodes, const std::string& name, const SystemSignature& system) {
  H5::Group group = episodes.createGroup(name);
  const hsize_t T = c.below(6);
  write_dataset(c, group, "t", T, 0, true);
  write_dataset(c, group, "x", T, system.states.size(), false);
  write_dataset(c, group, "u", T, system.controls.size(), false);
  if (c.below(8) == 0) group.createGroup("extra");
}

std::string episode_name(Choices& c, int index) {
  static const char* kNames[] = {"007", "-1", "x", "99999999999999999999999", "", " 1", "1e3", "0"};
  if (c.below(4) != 0) return std::to_string(index);
  std::string name = kNames[c.below(8)];
  if (name.empty()) name = c.text(6);
  return name;
}

/// Builds the HDF5 file the bytes describe.
void build_hdf5(Choices& c, const std::filesystem::path& file, const SystemSignature& system) {
  H5::H5File h5(file.c_str(), H5F_ACC_TRUNC);
  H5::Group root = h5.openGroup("/");
  static const char* kSystems[] = {"cartpole", "quadrotor", "", "cartpole\n"};
  std::string system_name = system.name;
  if (c.below(4) == 0) system_name = c.flag() ? kSystems[c.below(4)] : c.text(10);
  write_attribute(c, root, "system", {system_name}, true);
  write_attribute(c, root, "state_names", names_choice(c, names_of(system.states)), false);
  write_attribute(c, root, "control_names", names_choice(c, names_of(system.controls)), false);
  switch (c.below(8)) {
    case 0: return;  // no /episodes
    case 1: {
      const hsize_t dims[1] = {3};
      h5.createDataSet("episodes", H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, dims));
      return;
    }
    case 2: h5.link(H5L_TYPE_SOFT, "/nowhere", "episodes"); return;
    default: break;
  }
  H5::Group episodes = h5.createGroup("episodes");
  const int count = static_cast<int>(c.below(5));
  for (int k = 0; k < count; ++k) {
    const std::string name = episode_name(c, k);
    if (name.empty() || name.find('/') != std::string::npos || name == "." || episodes.nameExists(name)) continue;
    switch (c.below(10)) {
      case 0: {
        const hsize_t dims[1] = {2};
        episodes.createDataSet(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, dims));
        break;
      }
      case 1: episodes.link(H5L_TYPE_SOFT, "/episodes/none", name); break;
      case 2:
        if (k > 0 && episodes.getNumObjs() > 0) {
          episodes.link(H5L_TYPE_HARD, episodes.getObjnameByIdx(0), name);
          break;
        }
        [[fallthrough]];
      default: write_episode(c, episodes, name, system);
    }
  }
}

// ---------------------------------------------------------------------------------------------------
// TOML loaders

/// What read_solve_config promises (solve_config.hpp,
/// docs/formats.md#problem-config-gpilqg-solve-and-gpilqg-plan).
void check_solve_config(const SolveConfig& c) {
  const SystemSignature& system = system_named(c.system);
  const auto n = static_cast<Eigen::Index>(system.states.size());
  const auto m = static_cast<Eigen::Index>(system.controls.size());
  if (c.system != "cartpole" && c.system != "quadrotor") violated("unknown system accepted");
  if (!(c.dt > 0.0) || !std::isfinite(c.dt)) violated("dt " + std::to_string(c.dt) + " accepted");
  if (c.substeps < 1) violated("substeps < 1 accepted");
  if (c.horizon < 1) violated("horizon < 1 accepted");
  if (c.x0.size() != n || c.goal.size() != n || c.Q.size() != n || c.Qf.size() != n || c.R.size() != m)
    violated("wrong vector sizes accepted");
  for (const Vector* v : {&c.x0, &c.goal, &c.Q, &c.Qf, &c.R, &c.u_min, &c.u_max, &c.u_init})
    if (!v->allFinite()) violated("non-finite numbers accepted");
  for (const Vector* v : {&c.x0, &c.goal, &c.u_init})
    if (v->size() > 0 && v->cwiseAbs().maxCoeff() > kDivergedStateMagnitude) violated("a start beyond the divergence bound accepted");
  if ((c.Q.array() < 0).any() || (c.R.array() < 0).any() || (c.Qf.array() < 0).any())
    violated("negative weights accepted");
  if ((c.u_min.size() != 0 && c.u_min.size() != m) || (c.u_max.size() != 0 && c.u_max.size() != m) ||
      (c.u_init.size() != 0 && c.u_init.size() != m))
    violated("wrong control vector sizes accepted");
  if (c.u_min.size() != 0 && c.u_max.size() != 0 && (c.u_min.array() > c.u_max.array()).any())
    violated("u_min > u_max accepted");
  c.solver.validate();  // throws std::invalid_argument: escapes as a finding
}

struct TomlLoader {
  const char* name;
  void (*load)(const std::filesystem::path& file);
};

/// Every loader of a TOML file that the command line reads. Adding one is one line here (and a few
/// valid files in tests/fuzz/corpus/toml_configs/); each is run on every input and may throw only
/// InputError.
constexpr TomlLoader kTomlLoaders[] = {
    {"gpilqg solve config", [](const std::filesystem::path& file) { check_solve_config(read_solve_config(file)); }},
    {"gpilqg run cartpole config", [](const std::filesystem::path& file) { load_run_config("cartpole", file); }},
    {"gpilqg run quadrotor config", [](const std::filesystem::path& file) { load_run_config("quadrotor", file); }},
    {"gpilqg diagnose cartpole model", [](const std::filesystem::path& file) { diagnosis::read_model_file(file, "cartpole"); }},
    {"gpilqg diagnose quadrotor model", [](const std::filesystem::path& file) { diagnosis::read_model_file(file, "quadrotor"); }},
};

}  // namespace

const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    std::error_code error;
    std::filesystem::path base = "/dev/shm";
    if (!std::filesystem::is_directory(base, error)) base = std::filesystem::temp_directory_path();
    std::filesystem::path path = base / ("gpilqg-fuzz-" + std::to_string(static_cast<long>(::getpid())));
    std::filesystem::create_directories(path);
    return path;
  }();
  return dir;
}

void fuzz_measurements_csv(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const char* name : {"cartpole", "quadrotor"}) {
    const SystemSignature& system = system_named(name);
    read_and_check(system, "fuzz.csv", [&] { return parse_measurements_csv(text, "fuzz.csv", system); });
  }
  // The file path of the reader agrees with the in-memory one.
  const std::filesystem::path file = scratch_dir() / "input.csv";
  write_bytes(file, data, size);
  const SystemSignature& system = system_named("cartpole");
  read_and_check(system, file, [&] { return read_measurements_csv(file, system); });
}

void fuzz_measurements_hdf5(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = scratch_dir() / "input.h5";
  write_bytes(file, data, size);
  const SystemSignature& system = system_named("cartpole");
  read_and_check(system, file, [&] { return read_measurements_hdf5(file, system); });
}

void fuzz_measurements_hdf5_structured(const std::uint8_t* data, std::size_t size) {
  Choices choices(data, size);
  const SystemSignature& system = system_named(choices.flag() ? "quadrotor" : "cartpole");
  const std::filesystem::path file = scratch_dir() / "structured.h5";
  H5::Exception::dontPrint();
  try {
    build_hdf5(choices, file, system);
  } catch (const H5::Exception&) {
    return;  // a description the HDF5 library refuses to write (e.g. a chunk of size 0): nothing to read
  }
  read_and_check(system, file, [&] { return read_measurements_hdf5(file, system); });
}

void fuzz_toml_configs(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = scratch_dir() / "config.toml";
  write_bytes(file, data, size);
  for (const TomlLoader& loader : kTomlLoaders) {
    try {
      loader.load(file);
    } catch (const InputError& e) {
      if (std::string_view(e.what()).find(file.string()) == std::string_view::npos)
        violated(std::string(loader.name) + ": an InputError that does not name the file: " + e.what());
    }
  }
}

const std::vector<Target>& targets() {
  static const std::vector<Target> all{
      {"measurements_csv", &fuzz_measurements_csv},
      {"measurements_hdf5", &fuzz_measurements_hdf5},
      {"measurements_hdf5_structured", &fuzz_measurements_hdf5_structured},
      {"toml_configs", &fuzz_toml_configs},
  };
  return all;
}

}  // namespace gpilqg::fuzz
