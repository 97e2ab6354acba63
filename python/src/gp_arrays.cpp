#include "gp_arrays.hpp"

#include <cmath>
#include <sstream>

namespace gpilqg::python {

namespace {

/// NumPy's text for the shape, e.g. "(5,)" or "(3, 2)".
std::string shape_of(const py::array& array) { return py::str(array.attr("shape")); }

}  // namespace

void raise_input_error(const std::string& message) {
  const py::object type = py::module_::import("gpilqg._gpilqg").attr("InputError");
  PyErr_SetString(type.ptr(), message.c_str());
  throw py::error_already_set();
}

FortranArray checked_array(const py::handle& value, int ndim, const std::string& who, const std::string& name,
                           const std::string& shape_text) {
  auto array = FortranArray::ensure(value);
  if (!array)
    raise_input_error(who + ": " + name + " must be an array of real numbers of shape " + shape_text + "; got " +
                     std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  if (array.ndim() != ndim)
    raise_input_error(who + ": " + name + " must be a " + std::to_string(ndim) + "-D array of shape " + shape_text +
                     "; got shape " + shape_of(array));
  return array;
}

void require_finite(const FortranArray& array, const std::string& who, const std::string& name) {
  const double* data = array.data();
  for (py::ssize_t k = 0; k < array.size(); ++k) {
    if (std::isfinite(data[k])) continue;
    std::ostringstream os;
    os << who << ": " << name << "[";
    if (array.ndim() == 2)
      os << k % array.shape(0) << ", " << k / array.shape(0);  // Fortran order
    else
      os << k;
    os << "] = " << data[k] << " is not finite";
    raise_input_error(os.str());
  }
}

Eigen::Map<const Matrix> as_matrix(const FortranArray& array) {
  return {array.data(), static_cast<Eigen::Index>(array.shape(0)), static_cast<Eigen::Index>(array.shape(1))};
}

Eigen::Map<const Vector> as_vector(const FortranArray& array) {
  return {array.data(), static_cast<Eigen::Index>(array.shape(0))};
}

py::array model_view(const std::shared_ptr<const gp::FittedGp>& owner, const double* data,
                     std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides) {
  py::capsule keep_alive(new std::shared_ptr<const gp::FittedGp>(owner),
                         [](void* p) { delete static_cast<std::shared_ptr<const gp::FittedGp>*>(p); });
  py::array view(py::dtype::of<double>(), std::move(shape), std::move(strides), data, keep_alive);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return view;
}

}  // namespace gpilqg::python
