#pragma once
/// @file gp_arrays.hpp
/// NumPy arrays for the GP estimator: checked float64 inputs and read-only views into a fitted
/// model's memory.
///
/// Copies: a training set is owned by the model (TrainingSet holds column-major Eigen storage), so
/// fit() copies X and y once. Test inputs are read in place when they are a Fortran-ordered float64
/// array and converted once otherwise. Parameter vectors, training points and the backend extras
/// are returned as views of the model (kept alive by the view, so a refit does not invalidate them).

#include <memory>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg::python {

namespace py = pybind11;

/// Raises gpilqg.InputError (a ValueError) with `message`, through the Python type itself: the C++
/// gpilqg::InputError derives from std::runtime_error and has no translator of its own.
[[noreturn]] void raise_input_error(const std::string& message);

/// Column-major float64 array (converted from any array-like if needed).
using FortranArray = py::array_t<double, py::array::f_style | py::array::forcecast>;

/// `value` as a float64 array with `ndim` dimensions. Raises gpilqg.InputError naming `who` and
/// `name` ("X must be a 2-D array of shape (N, D); got shape (5,)") when it is not numeric or has
/// another number of dimensions. `shape_text` describes the expected shape, e.g. "(N, D)".
FortranArray checked_array(const py::handle& value, int ndim, const std::string& who, const std::string& name,
                           const std::string& shape_text);

/// Raises gpilqg.InputError naming the first entry that is NaN or infinite ("X[3, 1] = nan").
void require_finite(const FortranArray& array, const std::string& who, const std::string& name);

/// An Eigen view of a 2-D Fortran-ordered array (no copy).
Eigen::Map<const Matrix> as_matrix(const FortranArray& array);
/// An Eigen view of a 1-D array (no copy).
Eigen::Map<const Vector> as_vector(const FortranArray& array);

/// A read-only NumPy view of `data` (float64, the given shape and byte strides) inside `owner`'s
/// memory. The view holds a reference to `owner`, so the model lives as long as the view.
py::array model_view(const std::shared_ptr<const gp::FittedGp>& owner, const double* data,
                     std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides);

}  // namespace gpilqg::python
