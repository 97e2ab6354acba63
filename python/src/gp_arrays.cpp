#include "gp_arrays.hpp"

namespace gpilqg::python {

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
