#pragma once
/// @file conversions.hpp
/// What every part of the bindings shares: Python exceptions for the library's error types, the
/// checks of every argument that crosses from Python (type, shape against the system, finite
/// values) and of every array result, JSON documents as Python objects, and long calls that release
/// the GIL, report progress to a Python callback and stop on Ctrl-C.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <filesystem>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg::python {

namespace py = pybind11;

/// gpilqg.InputError (bad input: a config field, a data file; the command line's exit 2) and
/// gpilqg.DataError (a subclass: a measurement file), both ValueErrors, with the library's messages.
void register_errors(py::module_& m);

/// Raises gpilqg.InputError with `message` (the C++ InputError, which register_errors translates).
/// Thrown as a C++ exception, it passes through the library unchanged when a Python callback
/// (a builder, a Dynamics method) raises it from inside a library call.
[[noreturn]] void raise_input_error(const std::string& message);

/// A system given from Python: a registry name (str) or a gpilqg.Dynamics object. Anything else
/// (None, a number) raises gpilqg.InputError naming `who` and the argument `name`.
DynamicsPtr system_from_python(const py::object& system, const std::string& who = "system",
                               const std::string& name = "system");

/// A file path given from Python (str or os.PathLike). Anything else raises gpilqg.InputError
/// naming `who`, `name` and `expected` ("a measurement file path").
std::filesystem::path path_argument(const py::handle& value, const std::string& who, const std::string& name,
                                    const std::string& expected);

// --- Arrays across the boundary ---------------------------------------------------------------
// Every array argument is converted once (any array-like of real numbers), its number of dimensions
// and sizes are compared with what the system has, and its entries must be finite; a result array
// computed from finite arguments must be finite too. Each violation raises gpilqg.InputError that
// names the function (`who`), the argument and what was expected, e.g.
//   "Dynamics.derivatives: x has 3 entries; expected 4 (the states of system 'cartpole')".

/// Column-major float64 array (converted from any array-like if needed).
using FortranArray = py::array_t<double, py::array::f_style | py::array::forcecast>;

/// `value` as a float64 array with `ndim` dimensions; `shape_text` describes the expected shape,
/// e.g. "(N, D)". Raises gpilqg.InputError when it is not numeric or has another number of dimensions.
FortranArray checked_array(const py::handle& value, int ndim, const std::string& who, const std::string& name,
                           const std::string& shape_text);

/// Raises gpilqg.InputError naming the first entry that is NaN or infinite ("X[3, 1] = nan").
void require_finite(const FortranArray& array, const std::string& who, const std::string& name);

/// The quantities an array argument holds one value of, for the messages: their number and what
/// they are ("the states of system 'cartpole'").
struct Quantities {
  Eigen::Index count = 0;
  std::string what;
};

/// The states and the controls of a system, and of a step model (the system it integrates when it
/// knows it).
/// "system 'cartpole'" for a step model that integrates a known system (a residual model: its
/// simulator's), else "this step model".
std::string step_model_label(const StepModel& model);

Quantities states_of(const Dynamics& system);
Quantities controls_of(const Dynamics& system);
Quantities states_of(const StepModel& model);
Quantities controls_of(const StepModel& model);

/// Whether an array argument's entries must be finite. A Python callback's result may be left to
/// the caller (a diverging rollout is the library's status, not an error).
enum class Finite { Required, Unchecked };

/// A vector argument, shape (expected.count,), finite: a state x or a control u.
Vector vector_argument(const py::handle& value, const Quantities& expected, const std::string& who,
                       const std::string& name, Finite finite = Finite::Required);

/// A matrix argument of shape (rows, cols); `expected` says what the shape is ("fx = df/dx of system 'p'").
Matrix matrix_argument(const py::handle& value, Eigen::Index rows, Eigen::Index cols, const std::string& expected,
                       const std::string& who, const std::string& name, Finite finite = Finite::Required);

/// A matrix argument with one row per sample and one column per quantity, shape (N, expected.count)
/// with any N, finite.
Matrix rows_argument(const py::handle& value, const Quantities& expected, const std::string& who,
                     const std::string& name);

/// A result computed from finite arguments: raises gpilqg.InputError naming `who`, the result `name`,
/// its first non-finite entry and `context` (where it was evaluated) when it is not finite. Never a
/// NaN returned to Python.
void require_finite_result(const Vector& value, const std::string& who, const std::string& name,
                           const std::string& context);
void require_finite_result(const Matrix& value, const std::string& who, const std::string& name,
                           const std::string& context);

/// A JSON document as the Python object json.loads would give (dicts, lists, floats, None).
py::object to_python(const nlohmann::json& document);

/// Ctrl-C and progress for one long call. The call runs with the GIL released; `checkpoint` (called
/// by the library between iterations, on the calling thread) takes the GIL, passes `line` to the
/// Python callback when there is one, and lets Python handle pending signals: after Ctrl-C it returns
/// false (or throws Interrupted from throwing_checkpoint), and the binding raises KeyboardInterrupt.
class LongCall {
 public:
  /// Raises gpilqg.InputError when `progress` is neither None nor callable.
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
