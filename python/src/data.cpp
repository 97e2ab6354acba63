/// Measurement sets (docs/formats.md#measurement-data-csv-and-hdf5) from Python: from arrays, from
/// files, and (in the package's Python part) from pandas DataFrames. An episode's arrays are read-only
/// NumPy views of the set's memory, never copies.

#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "gp_arrays.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg::python {
namespace {

/// (t, x, u) -> an Episode, or (t, x) for a system without controls (m = 0); shapes are checked with
/// the whole set (check_measurement_set).
Episode episode_of(const py::handle& item, long id, bool passive) {
  const bool sequence = py::isinstance<py::tuple>(item) || py::isinstance<py::list>(item);
  const std::size_t size = sequence ? py::len(item) : 0;
  if (size != 3 && !(passive && size == 2))
    throw InputError(fmt::format("episode {}: expected a tuple (t, x, u){}", id,
                                 passive ? " or (t, x) (the system has no controls)" : ""));
  const py::sequence parts = py::reinterpret_borrow<py::sequence>(item);
  const std::string who = fmt::format("MeasurementSet: episode {}", id);
  Episode e;
  e.id = id;
  e.t = as_vector(checked_array(parts[0], 1, who, "t", "(T,)"));
  e.x = as_matrix(checked_array(parts[1], 2, who, "x", "(T, n)"));
  e.u = size == 3 ? Matrix(as_matrix(checked_array(parts[2], 2, who, "u", "(T, m)"))) : Matrix(e.t.size(), 0);
  return e;
}

MeasurementSet make_set(const py::object& system, const py::list& episodes, const std::vector<long>& ids) {
  MeasurementSet set;
  set.system = system_from_python(system, "MeasurementSet")->signature();
  if (!ids.empty() && ids.size() != episodes.size())
    throw InputError(fmt::format("ids: {} ids for {} episodes", ids.size(), episodes.size()));
  for (std::size_t i = 0; i < episodes.size(); ++i)
    set.episodes.push_back(
        episode_of(episodes[i], ids.empty() ? static_cast<long>(i) : ids[i], set.system.controls.empty()));
  try {
    check_measurement_set(set);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return set;
}

}  // namespace

void bind_data(py::module_& m) {
  py::class_<Episode>(m, "Episode", "One episode of a measurement set: T samples at a constant step.")
      .def_readonly("id", &Episode::id, "the episode's id (the CSV's `episode` value)")
      .def_property_readonly("t", [](const Episode& e) -> const Vector& { return e.t; },
                             py::return_value_policy::reference_internal, "times [s], shape (T,) (a read-only view)")
      .def_property_readonly("x", [](const Episode& e) -> const Matrix& { return e.x; },
                             py::return_value_policy::reference_internal,
                             "measured states, shape (T, n) (a read-only view)")
      .def_property_readonly("u", [](const Episode& e) -> const Matrix& { return e.u; },
                             py::return_value_policy::reference_internal,
                             "applied controls, shape (T, m): u[k] acts from t[k] to t[k+1] (a read-only view)")
      .def_property_readonly("dt", &Episode::dt)
      .def("__len__", &Episode::length);

  py::class_<MeasurementSet>(m, "MeasurementSet", R"(
Measured episodes of one system (docs/formats.md#measurement-data-csv-and-hdf5): per episode the
measured state at each time and the control applied from then until the next sample, at a constant
step.)")
      .def(py::init(&make_set), py::arg("system"), py::arg("episodes"), py::arg("ids") = std::vector<long>{},
           R"(system: a registry name or gpilqg.Dynamics; episodes: a list of (t (T,), x (T, n), u (T, m)), or of
(t, x) for a system without controls (m = 0, u then has shape (T, 0)); ids: the episode ids (default 0, 1, ...). Raises InputError naming the episode and sample for wrong
shapes, non-finite values, or times that do not increase at a constant step.)")
      .def_property_readonly("system", [](const MeasurementSet& s) { return s.system.name; })
      .def_property_readonly("state_names", [](const MeasurementSet& s) { return names_of(s.system.states); })
      .def_property_readonly("control_names", [](const MeasurementSet& s) { return names_of(s.system.controls); })
      .def_property_readonly("episodes", [](py::object self) {
        py::list out;
        for (Episode& e : self.cast<MeasurementSet&>().episodes)
          out.append(py::cast(&e, py::return_value_policy::reference_internal, self));
        return out;
      }, "the episodes, in order (views into the set)")
      .def_property(
          "estimated_states", [](const MeasurementSet& s) { return s.estimated_states; },
          [](MeasurementSet& s, const std::vector<std::string>& names) {
            std::vector<std::string> previous = std::move(s.estimated_states);
            s.estimated_states = names;
            try {
              check_measurement_set(s);
            } catch (const std::invalid_argument& e) {
              s.estimated_states = std::move(previous);
              throw InputError(e.what());
            }
          },
          "the states estimated from others rather than measured (e.g. velocities differentiated from positions); "
          "[] when all were measured. Kept by HDF5 files (attribute estimated_states), not by CSV.")
      .def_property_readonly("sample_count", &MeasurementSet::sample_count)
      .def("write", [](const MeasurementSet& s, const std::filesystem::path& file) { write_measurements(file, s); },
           py::arg("file"), "Writes CSV or HDF5 by the file's extension, atomically.");

  m.def("read_measurements",
        [](const std::filesystem::path& file, const py::object& system) {
          return read_measurements(file, system_from_python(system, "read_measurements")->signature());
        },
        py::arg("file"), py::arg("system"),
        "Reads and validates a CSV or HDF5 measurement file; raises DataError naming the file and line or dataset.");
}

}  // namespace gpilqg::python
