#include "conversions.hpp"

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg::python {

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

LongCall::LongCall(py::object progress) : progress_(std::move(progress)) {}

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
