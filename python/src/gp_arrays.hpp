#pragma once
/// @file gp_arrays.hpp
/// NumPy arrays for the GP estimator: Eigen views of checked inputs (checked_array in
/// conversions.hpp) and read-only views into a fitted model's memory.
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

#include "conversions.hpp"
#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg::python {

namespace py = pybind11;

/// An Eigen view of a 2-D Fortran-ordered array (no copy).
Eigen::Map<const Matrix> as_matrix(const FortranArray& array);
/// An Eigen view of a 1-D array (no copy).
Eigen::Map<const Vector> as_vector(const FortranArray& array);

/// A read-only NumPy view of `data` (float64, the given shape and byte strides) inside `owner`'s
/// memory. The view holds a reference to `owner`, so the model lives as long as the view.
py::array model_view(const std::shared_ptr<const gp::FittedGp>& owner, const double* data,
                     std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides);

}  // namespace gpilqg::python
