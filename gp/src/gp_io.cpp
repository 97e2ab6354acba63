#include "gpilqg/gp/gp_io.hpp"

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/dataset_size.hpp"
#include "gpilqg/core/hdf5_memory_file.hpp"
#include "gpilqg/core/hdf5_self_contained.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"

#include <H5Cpp.h>

#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace gpilqg::gp {

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
constexpr int kFormatVersion = 1;

std::string where(const std::filesystem::path& file, const std::string& object) {
  return file.string() + ":" + object;
}

/// Runs `action`, turning an HDF5 failure into std::runtime_error naming the file and the object.
template <class Action>
auto guarded(const std::filesystem::path& file, const std::string& object, const std::string& what, Action&& action)
    -> decltype(action()) {
  try {
    return action();
  } catch (const H5::Exception& e) {
    std::string detail = e.getDetailMsg();
    if (detail.empty()) detail = e.getFuncName();
    throw std::runtime_error(where(file, object) + ": " + what + " failed (HDF5: " + detail + ")");
  }
}

void write_string_attribute(H5::Group& group, const std::string& name, const std::string& value) {
  const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  const char* data = value.c_str();
  group.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, &data);
}

template <class T>
void write_scalar_attribute(H5::Group& group, const std::string& name, const H5::PredType& file_type,
                            const H5::PredType& memory_type, T value) {
  group.createAttribute(name, file_type, H5::DataSpace(H5S_SCALAR)).write(memory_type, &value);
}

void write_dataset(H5::Group& group, const std::string& name, const RowMajor& values, bool one_dimensional) {
  const hsize_t dims[2] = {static_cast<hsize_t>(one_dimensional ? values.size() : values.rows()),
                           static_cast<hsize_t>(values.cols())};
  const H5::DataSpace space(one_dimensional ? 1 : 2, dims);
  const H5::DataSet data = group.createDataSet(name, H5::PredType::IEEE_F64LE, space);
  if (values.size() > 0) data.write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

std::string normalised(const std::filesystem::path& file, const std::string& group) {
  if (group.empty() || group == "/")
    throw std::invalid_argument(file.string() + ": group '" + group + "': expected a group name below /");
  return group.front() == '/' ? group : "/" + group;
}

/// What a saved GP file must be before it is opened (input_file.hpp); returns its size in bytes.
std::uintmax_t check_gp_file(const std::filesystem::path& file) {
  return check_input_file(file, kMaxDataFileBytes, "an HDF5 file holding a saved GP");
}

/// Refuses a dataset or attribute that declares more values than the file can hold or than
/// kMaxDatasetValues (dataset_size.hpp), before anything is allocated for it.
void check_declared_size(const std::filesystem::path& file, const std::string& object, hid_t id,
                         std::uintmax_t file_bytes) {
  std::optional<std::string> problem;
  try {
    problem = hdf5_size_problem(id, file_bytes);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(where(file, object) + ": " + e.what());
  }
  if (problem)
    throw DataError(file, object, *problem,
                    "a dataset that fits the file and at most " + std::to_string(kMaxDatasetValues) + " values");
}

/// Reads a scalar attribute (exactly one value) as `type` into `value`; an attribute of another size
/// would overflow `value`.
template <class T>
void read_scalar_attribute(const std::filesystem::path& file, const H5::Group& group, const std::string& object,
                           const std::string& name, const H5::PredType& type, T& value) {
  const H5::Attribute a = group.openAttribute(name);
  if (a.getSpace().getSimpleExtentNpoints() != 1)
    throw DataError(file, object + " attribute '" + name + "'",
                    "holds " + std::to_string(a.getSpace().getSimpleExtentNpoints()) + " values", "a single number");
  a.read(type, &value);
}

/// Runs `load`, making every error it throws start with "<file>:<object>: " (a backend's message
/// about the data it is conditioned on does not know the file).
template <class Load>
auto naming_the_file(const std::filesystem::path& file, const std::string& object, Load&& load) -> decltype(load()) {
  const auto prefixed = [&](const std::exception& e) {
    const std::string what = e.what();
    return what.rfind(file.string(), 0) == 0 ? what : where(file, object) + ": " + what;
  };
  try {
    return load();
  } catch (const DataError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(prefixed(e));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(prefixed(e));
  }
}

}  // namespace

namespace {

/// Whether the absolute path exists; H5Lexists fails (rather than saying no) when an intermediate
/// group is missing, so the path is checked one component at a time.
bool path_exists(const H5::H5File& h5, const std::string& path) {
  for (std::size_t end = path.find('/', 1);; end = path.find('/', end + 1)) {
    if (!h5.nameExists(path.substr(0, end))) return false;
    if (end == std::string::npos) return true;
  }
}

/// Writes `model` to `group_path` of the open file, replacing a group of that name.
void write_fitted_gp(H5::H5File& h5, const std::string& group_path, const FittedGp& model) {
  if (path_exists(h5, group_path)) h5.unlink(group_path);
  H5::LinkCreatPropList intermediate;
  H5Pset_create_intermediate_group(intermediate.getId(), 1);
  // (Not H5::Group(H5Gcreate2(...)): that constructor takes a second reference to the id, so the group
  // and with it the file stayed open after close(), unflushed.)
  H5::Group group = h5.createGroup(group_path, intermediate);
  write_string_attribute(group, "backend", std::string(model.backend_name()));
  write_scalar_attribute(group, "format_version", H5::PredType::STD_I32LE, H5::PredType::NATIVE_INT, kFormatVersion);
  write_scalar_attribute(group, "input_dim", H5::PredType::STD_I32LE, H5::PredType::NATIVE_INT, model.input_dim());
  write_scalar_attribute(group, "jitter", H5::PredType::IEEE_F64LE, H5::PredType::NATIVE_DOUBLE,
                         model.conditioning().jitter);
  write_scalar_attribute(group, "negative_log_marginal_likelihood", H5::PredType::IEEE_F64LE,
                         H5::PredType::NATIVE_DOUBLE, model.negative_log_marginal_likelihood());
  write_dataset(group, "parameters", model.parameters().transpose(), true);
  write_dataset(group, "inputs", model.training_set().inputs, false);
  write_dataset(group, "targets", model.training_set().targets.transpose(), true);
  if (model.training_set().noise_variance.size() > 0)
    write_dataset(group, "noise_variance", model.training_set().noise_variance.transpose(), true);
}

/// Runs `edit` on `file` opened for writing (created when missing) as one atomic update: the edit
/// happens on a copy that replaces `file` only when it succeeded (atomic_file.hpp), so a failure
/// half-way never leaves a damaged file behind.
void edit_atomically(const std::filesystem::path& file, const std::string& object, const std::string& what,
                     const std::function<void(H5::H5File&)>& edit) {
  H5::Exception::dontPrint();
  guarded(file, object, what, [&] {
    update_hdf5_atomically(file, edit);
    return 0;
  });
}

}  // namespace

void save_fitted_gp(const std::filesystem::path& file, const std::string& group_name, const FittedGp& model) {
  const std::string group_path = normalised(file, group_name);
  edit_atomically(file, group_path, "writing the fitted GP",
                  [&](H5::H5File& h5) { write_fitted_gp(h5, group_path, model); });
}

std::unique_ptr<FittedGp> load_fitted_gp(const std::filesystem::path& file, const std::string& group_name,
                                         const GpBackend& backend) {
  const std::string group_path = normalised(file, group_name);
  H5::Exception::dontPrint();
  const std::uintmax_t file_bytes = check_gp_file(file);
  auto fail = [&](const std::string& object, const std::string& problem) -> std::runtime_error {
    return std::runtime_error(where(file, object) + ": " + problem);
  };
  H5::H5File h5 = guarded(file, "/", "opening", [&] { return H5::H5File(file.c_str(), H5F_ACC_RDONLY); });
  check_hdf5_self_contained(file, h5.getId());
  if (!guarded(file, group_path, "looking up", [&] { return path_exists(h5, group_path); }))
    throw fail(group_path, "no such group; expected a saved GP");
  const H5::Group group = guarded(file, group_path, "opening", [&] { return h5.openGroup(group_path); });

  auto attribute_exists = [&](const std::string& name) { return group.attrExists(name); };
  for (const char* name : {"backend", "input_dim"})
    if (!attribute_exists(name)) throw fail(group_path + " attribute '" + name + "'", "missing");
  const std::string stored_backend = guarded(file, group_path + " attribute 'backend'", "reading", [&] {
    const H5::Attribute a = group.openAttribute("backend");
    check_declared_size(file, group_path + " attribute 'backend'", a.getId(), file_bytes);
    std::string value;
    a.read(a.getStrType(), value);
    return value;
  });
  if (stored_backend != backend.name())
    throw fail(group_path + " attribute 'backend'",
               "is '" + stored_backend.substr(0, 40) + "'; expected '" + std::string(backend.name()) + "' (the backend given)");
  const int input_dim = guarded(file, group_path + " attribute 'input_dim'", "reading", [&] {
    int value = 0;
    read_scalar_attribute(file, group, group_path, "input_dim", H5::PredType::NATIVE_INT, value);
    return value;
  });

  auto read = [&](const std::string& name, int rank) {
    const std::string object = group_path + "/" + name;
    if (!group.nameExists(name)) throw fail(object, "missing dataset");
    return guarded(file, object, "reading", [&] {
      const H5::DataSet data = group.openDataSet(name);
      const H5::DataSpace space = data.getSpace();
      if (space.getSimpleExtentNdims() != rank)
        throw fail(object, "has rank " + std::to_string(space.getSimpleExtentNdims()) + "; expected " +
                               std::to_string(rank));
      check_declared_size(file, object, data.getId(), file_bytes);
      hsize_t dims[2] = {0, 1};
      space.getSimpleExtentDims(dims);
      RowMajor values(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(rank == 2 ? dims[1] : 1));
      if (values.size() > 0) data.read(values.data(), H5::PredType::NATIVE_DOUBLE);
      return values;
    });
  };
  const RowMajor parameters = read("parameters", 1);
  TrainingSet data;
  data.inputs = read("inputs", 2);
  data.targets = read("targets", 1).col(0);
  if (data.inputs.cols() != input_dim)
    throw fail(group_path + "/inputs", "has " + std::to_string(data.inputs.cols()) + " columns; expected input_dim = " +
                                           std::to_string(input_dim));
  if (data.targets.size() != data.inputs.rows())
    throw fail(group_path + "/targets", "has " + std::to_string(data.targets.size()) + " entries; expected " +
                                            std::to_string(data.inputs.rows()) + " (one per input row)");
  if (group.nameExists("noise_variance")) {  // known noise variances (TrainingSet::noise_variance)
    data.noise_variance = read("noise_variance", 1).col(0);
    if (data.noise_variance.size() != data.targets.size())
      throw fail(group_path + "/noise_variance", "has " + std::to_string(data.noise_variance.size()) +
                                                     " entries; expected " + std::to_string(data.targets.size()) +
                                                     " (one per target)");
  }
  return naming_the_file(file, group_path, [&] { return backend.condition(std::move(data), parameters.col(0)); });
}

void save_residual_model(const std::filesystem::path& file, const std::string& group_name, const ResidualModel& model) {
  const std::string group_path = normalised(file, group_name);
  edit_atomically(file, group_path, "writing the residual model", [&](H5::H5File& h5) {
    for (int i = 0; i < model.state_dim(); ++i)
      write_fitted_gp(h5, group_path + "/" + std::to_string(i), model.output(i));
    H5::Group group = h5.openGroup(group_path);
    for (const char* name : {"state_dim", "control_dim", "dt"})
      if (group.attrExists(name)) group.removeAttr(name);
    write_scalar_attribute(group, "state_dim", H5::PredType::STD_I32LE, H5::PredType::NATIVE_INT, model.state_dim());
    write_scalar_attribute(group, "control_dim", H5::PredType::STD_I32LE, H5::PredType::NATIVE_INT,
                           model.control_dim());
    write_scalar_attribute(group, "dt", H5::PredType::IEEE_F64LE, H5::PredType::NATIVE_DOUBLE, model.dt());
  });
}

ResidualModel load_residual_model(const std::filesystem::path& file, const std::string& group_name,
                                  ResidualModel::SimulatorPtr simulator, const GpBackend& backend) {
  if (!simulator) throw std::invalid_argument(file.string() + ": load_residual_model: null simulator");
  const std::string group_path = normalised(file, group_name);
  check_gp_file(file);
  H5::Exception::dontPrint();
  struct Stored {
    int state_dim = 0, control_dim = 0;
    double dt = 0.0;
  };
  const Stored stored = guarded(file, group_path, "reading the residual model's attributes", [&] {
    const H5::H5File h5(file.c_str(), H5F_ACC_RDONLY);
    check_hdf5_self_contained(file, h5.getId());
    if (!path_exists(h5, group_path)) throw std::runtime_error(where(file, group_path) + ": no such group");
    const H5::Group group = h5.openGroup(group_path);
    Stored s;
    for (const char* name : {"state_dim", "control_dim", "dt"})
      if (!group.attrExists(name))
        throw std::runtime_error(where(file, group_path + " attribute '" + name + "'") + ": missing");
    read_scalar_attribute(file, group, group_path, "state_dim", H5::PredType::NATIVE_INT, s.state_dim);
    read_scalar_attribute(file, group, group_path, "control_dim", H5::PredType::NATIVE_INT, s.control_dim);
    read_scalar_attribute(file, group, group_path, "dt", H5::PredType::NATIVE_DOUBLE, s.dt);
    return s;
  });
  if (stored.state_dim != simulator->state_dim() || stored.control_dim != simulator->control_dim() ||
      !(std::abs(stored.dt - simulator->dt()) <= 1e-6 * simulator->dt()))
    throw std::runtime_error(where(file, group_path) + ": saved for " + std::to_string(stored.state_dim) + " states, " +
                             std::to_string(stored.control_dim) + " controls, dt " + std::to_string(stored.dt) +
                             "; expected the simulator's " + std::to_string(simulator->state_dim()) + ", " +
                             std::to_string(simulator->control_dim()) + ", " + std::to_string(simulator->dt()));
  std::vector<std::unique_ptr<FittedGp>> outputs;
  for (int i = 0; i < stored.state_dim; ++i)
    outputs.push_back(load_fitted_gp(file, group_path + "/" + std::to_string(i), backend));
  return naming_the_file(file, group_path, [&] { return ResidualModel(std::move(simulator), std::move(outputs)); });
}

}  // namespace gpilqg::gp
