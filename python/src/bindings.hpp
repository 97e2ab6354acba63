#pragma once
/// @file bindings.hpp
/// The parts of the extension module gpilqg._gpilqg, one source file each. Arrays cross as NumPy
/// float64 arrays: a state is shape (n,), a trajectory (T+1, n) with one row per time step (the
/// layout of the data files and the HDF5 results), a Jacobian (n, n + m).

#include <pybind11/pybind11.h>

namespace gpilqg::python {

namespace py = pybind11;

void bind_systems(py::module_& m);    ///< systems.cpp: systems, step models, Python-defined dynamics, plugins
void bind_data(py::module_& m);       ///< data.cpp: measurement sets
void bind_gp(py::module_& m);         ///< gp.cpp: the GP backends as estimators
void bind_residual_model(py::module_& m);  ///< residual_model.cpp: simulator + GP residual
void bind_workflows(py::module_& m);  ///< workflows.cpp: diagnose, solve, plan, run, policies

}  // namespace gpilqg::python
