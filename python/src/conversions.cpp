#include "conversions.hpp"

#include <cmath>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <pybind11/stl/filesystem.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::python {

namespace {

/// NumPy's text for the shape, e.g. "(5,)" or "(3, 2)".
std::string shape_of(const py::array& array) { return py::str(array.attr("shape")); }

/// The Python type's name of `value` ("NoneType", "str").
std::string type_name(const py::handle& value) { return py::str(py::type::handle_of(value).attr("__name__")); }

/// The first NaN or infinite entry of a column-major rows x cols block as "[i]" or "[i, j]" with its
/// value ("[3] = nan"), or "" when all are finite.
std::string first_non_finite(const double* data, Eigen::Index rows, Eigen::Index cols, bool vector) {
  for (Eigen::Index k = 0; k < rows * cols; ++k) {
    if (std::isfinite(data[k])) continue;
    std::ostringstream os;
    os << "[";
    if (vector) os << k;
    else os << k % rows << ", " << k / rows;
    os << "] = " << data[k];
    return os.str();
  }
  return "";
}

/// The array-like `value` as a float64 array, or nothing for what is not one (None, a str, a list of
/// lists of different lengths).
std::optional<FortranArray> to_array(const py::handle& value) {
  if (value.is_none() || py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value)) return std::nullopt;
  FortranArray array = FortranArray::ensure(value);
  if (!array) return std::nullopt;
  return array;
}

/// The array-like `value` as a float64 array of `ndim` dimensions; the message says what was expected.
FortranArray array_argument(const py::handle& value, int ndim, const std::string& who, const std::string& name,
                            const std::string& expected) {
  const std::optional<FortranArray> array = to_array(value);
  if (!array) raise_input_error(fmt::format("{}: {} is {}; expected {}", who, name, type_name(value), expected));
  if (array->ndim() != ndim)
    raise_input_error(fmt::format("{}: {} has shape {}; expected {}", who, name, shape_of(*array), expected));
  return *array;
}

std::string signature_text(const Quantities& q, bool rows) {
  return rows ? fmt::format("shape (N, {}) ({})", q.count, q.what) : fmt::format("shape ({},) ({})", q.count, q.what);
}

}  // namespace

void raise_input_error(const std::string& message) { throw InputError(message); }

std::filesystem::path path_argument(const py::handle& value, const std::string& who, const std::string& name,
                                    const std::string& expected) {
  if (py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__")) {
    const py::object text = py::module_::import("os").attr("fspath")(value);
    if (py::isinstance<py::str>(text)) return text.cast<std::filesystem::path>();
  }
  raise_input_error(fmt::format("{}: {} is {}; expected {} (str or os.PathLike)", who, name, type_name(value), expected));
}

FortranArray checked_array(const py::handle& value, int ndim, const std::string& who, const std::string& name,
                           const std::string& shape_text) {
  const std::optional<FortranArray> array = to_array(value);
  if (!array)
    raise_input_error(fmt::format("{}: {} must be an array of real numbers of shape {}; got {}", who, name, shape_text,
                                  type_name(value)));
  if (array->ndim() != ndim)
    raise_input_error(fmt::format("{}: {} must be a {}-D array of shape {}; got shape {}", who, name, ndim, shape_text,
                                  shape_of(*array)));
  return *array;
}

void require_finite(const FortranArray& array, const std::string& who, const std::string& name) {
  const bool vector = array.ndim() != 2;
  const std::string entry = first_non_finite(array.data(), vector ? array.size() : array.shape(0),
                                             vector ? 1 : array.shape(1), vector);
  if (!entry.empty()) raise_input_error(fmt::format("{}: {}{} is not finite", who, name, entry));
}

Quantities states_of(const Dynamics& system) {
  return {system.state_dim(), fmt::format("the states of system '{}'", system.name())};
}

Quantities controls_of(const Dynamics& system) {
  return {system.control_dim(), fmt::format("the controls of system '{}'", system.name())};
}

std::string step_model_label(const StepModel& model) {
  if (const auto* integrated = dynamic_cast<const IntegratedStepModel*>(&model))
    return fmt::format("system '{}'", integrated->dynamics().name());
  if (const auto* residual = dynamic_cast<const gp::ResidualModel*>(&model))
    return step_model_label(residual->simulator());
  return "this step model";
}

Quantities states_of(const StepModel& model) {
  return {model.state_dim(), "the states of " + step_model_label(model)};
}

Quantities controls_of(const StepModel& model) {
  return {model.control_dim(), "the controls of " + step_model_label(model)};
}

Vector vector_argument(const py::handle& value, const Quantities& expected, const std::string& who,
                       const std::string& name, Finite finite) {
  const FortranArray array = array_argument(value, 1, who, name, signature_text(expected, false));
  if (array.shape(0) != expected.count)
    raise_input_error(fmt::format("{}: {} has {} entries; expected {} ({})", who, name, array.shape(0), expected.count,
                                  expected.what));
  if (finite == Finite::Required) require_finite(array, who, name);
  return Eigen::Map<const Vector>(array.data(), expected.count);
}

Matrix matrix_argument(const py::handle& value, Eigen::Index rows, Eigen::Index cols, const std::string& expected,
                       const std::string& who, const std::string& name, Finite finite) {
  const std::string shape = fmt::format("shape ({}, {}) ({})", rows, cols, expected);
  const FortranArray array = array_argument(value, 2, who, name, shape);
  if (array.shape(0) != rows || array.shape(1) != cols)
    raise_input_error(fmt::format("{}: {} has shape {}; expected {}", who, name, shape_of(array), shape));
  if (finite == Finite::Required) require_finite(array, who, name);
  return Eigen::Map<const Matrix>(array.data(), rows, cols);
}

Matrix rows_argument(const py::handle& value, const Quantities& expected, const std::string& who,
                     const std::string& name) {
  const FortranArray array = array_argument(value, 2, who, name, signature_text(expected, true));
  if (array.shape(1) != expected.count)
    raise_input_error(fmt::format("{}: {} has {} columns; expected {} ({})", who, name, array.shape(1), expected.count,
                                  expected.what));
  require_finite(array, who, name);
  return Eigen::Map<const Matrix>(array.data(), array.shape(0), expected.count);
}

void require_finite_result(const Vector& value, const std::string& who, const std::string& name,
                           const std::string& context) {
  const std::string entry = first_non_finite(value.data(), value.size(), 1, true);
  if (!entry.empty())
    raise_input_error(fmt::format("{}: the result {}{} is not finite at {}; expected finite values", who, name, entry, context));
}

void require_finite_result(const Matrix& value, const std::string& who, const std::string& name,
                           const std::string& context) {
  const std::string entry = first_non_finite(value.data(), value.rows(), value.cols(), false);
  if (!entry.empty())
    raise_input_error(fmt::format("{}: the result {}{} is not finite at {}; expected finite values", who, name, entry, context));
}

void register_errors(py::module_& m) {
  auto& input_error = py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  auto& data_error = py::register_exception<DataError>(m, "DataError", input_error.ptr());
  input_error.attr("__doc__") = "Bad input (a config field, an option, a file): the command line's exit status 2.";
  data_error.attr("__doc__") = "A measurement file that breaks the data format; the message names the file and line.";
  // std::invalid_argument from the library becomes ValueError (pybind11's default translation).
}

py::object to_python(const nlohmann::json& document) {
  return py::module_::import("json").attr("loads")(document.dump());
}

LongCall::LongCall(py::object progress) : progress_(std::move(progress)) {
  if (!progress_.is_none() && !PyCallable_Check(progress_.ptr()))
    raise_input_error(fmt::format("progress is {}; expected a callable progress(line) or None", type_name(progress_)));
}

bool LongCall::checkpoint(const std::string& line) {
  if (interrupted_) return false;
  py::gil_scoped_acquire acquire;
  try {
    if (!progress_.is_none() && !line.empty()) progress_(line);
  } catch (py::error_already_set& e) {  // the callback's exception is the call's result
    pending_ = std::make_shared<py::error_already_set>(std::move(e));
    interrupted_ = true;
    return false;
  }
  if (PyErr_CheckSignals() != 0) {  // a signal handler raised (KeyboardInterrupt after Ctrl-C)
    pending_ = std::make_shared<py::error_already_set>();
    interrupted_ = true;
    return false;
  }
  return true;
}

void LongCall::throwing_checkpoint(const std::string& line) {
  if (!checkpoint(line)) throw Interrupted{};
}

void LongCall::raise_if_interrupted() {
  if (pending_) throw py::error_already_set(*pending_);
}

}  // namespace gpilqg::python
