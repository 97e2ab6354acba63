#pragma once
/// @file conversions.hpp
/// What every part of the bindings shares: Python exceptions for the library's error types, JSON
/// documents as Python objects, and long calls that release the GIL, report progress to a Python
/// callback and stop on Ctrl-C.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

#include "gpilqg/core/dynamics.hpp"

namespace gpilqg::python {

namespace py = pybind11;

/// gpilqg.InputError (bad input: a config field, a data file; the command line's exit 2) and
/// gpilqg.DataError (a subclass: a measurement file), both ValueErrors, with the library's messages.
void register_errors(py::module_& m);

/// A system given from Python: a registry name (str) or a gpilqg.Dynamics object.
DynamicsPtr system_from_python(const py::object& system);

/// A JSON document as the Python object json.loads would give (dicts, lists, floats, None).
py::object to_python(const nlohmann::json& document);

/// Ctrl-C and progress for one long call. The call runs with the GIL released; `checkpoint` (called
/// by the library between iterations, on the calling thread) takes the GIL, passes `line` to the
/// Python callback when there is one, and lets Python handle pending signals: after Ctrl-C it returns
/// false (or throws Interrupted from throwing_checkpoint), and the binding raises KeyboardInterrupt.
class LongCall {
 public:
  explicit LongCall(py::object progress = py::none());
  /// True to go on; false after a Python signal handler raised (KeyboardInterrupt) or the callback did.
  bool checkpoint(const std::string& line = "");
  /// checkpoint() that throws Interrupted instead of returning false.
  void throwing_checkpoint(const std::string& line = "");
  /// Runs `work` without the GIL, then raises the pending Python exception if a checkpoint saw one.
  template <typename Result>
  Result run(const std::function<Result()>& work) {
    std::optional<Result> result;
    {
      py::gil_scoped_release release;
      try {
        result = work();
      } catch (const Interrupted&) {
      }
    }
    raise_if_interrupted();
    if (!result) {  // stopped without a pending Python exception: still a stop, never a made-up result
      PyErr_SetString(PyExc_KeyboardInterrupt, "the call was interrupted");
      throw py::error_already_set();
    }
    return std::move(*result);
  }

  /// Thrown through the library to stop it; never derived from std::exception, so the library's
  /// handlers of its own errors let it pass.
  struct Interrupted {};

 private:
  /// With the GIL held: throws py::error_already_set for the exception a checkpoint left pending.
  void raise_if_interrupted();
  py::object progress_;
  bool interrupted_ = false;
  /// The exception that stopped the call, taken out of Python's error indicator so that the library
  /// may still call into Python (a Python system) while it winds down; raised when the call returns.
  std::shared_ptr<py::error_already_set> pending_;
};

}  // namespace gpilqg::python
