/// The extension module gpilqg._gpilqg; the package gpilqg (python/gpilqg/__init__.py) re-exports it.

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "gpilqg/core/version.hpp"

PYBIND11_MODULE(_gpilqg, m) {
  namespace gp = gpilqg::python;
  m.doc() = "gpilqg: GP-corrected simulators and Robust-iLQG (C++ library bindings)";
  m.attr("__version__") = gpilqg::kVersionString;
  gp::register_errors(m);
  gp::bind_systems(m);
  gp::bind_data(m);
  gp::bind_gp(m);
  gp::bind_residual_model(m);
  gp::bind_workflows(m);
}
