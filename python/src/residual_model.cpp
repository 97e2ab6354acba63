/// The residual model from Python (gp/residual_model.hpp): the simulator as the mean function of one
/// GP per state that learns only its one-step error, d(x, u) = x'_measured - phi_sim(x, u). It is a
/// StepModel (step and Jacobians of simulator + GP mean), and predicts the correction with its std.

#include <optional>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/noise_floor.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::python {

void bind_residual_model(py::module_& m) {
  py::class_<gp::ResidualModel, StepModel, std::shared_ptr<gp::ResidualModel>>(m, "ResidualModel", R"(
Simulator + GP residual (the paper's model): x' = phi_sim(x, u) + mu(z) with z = [x; u] and one GP
per state on the measured one-step errors. step() and jacobians() use the GP mean; predict() gives the
correction and its std.)")
      .def_static(
          "fit",
          [](const std::shared_ptr<StepModel>& simulator, const MeasurementSet& data, const std::string& backend,
             int exact_points, int inducing, int frequencies, int restarts, int max_evaluations, std::uint64_t seed,
             const py::object& observation_std_in) {
            if (!simulator) raise_input_error("ResidualModel.fit: simulator is None; expected a gpilqg.StepModel");
            std::optional<Vector> observation_std;
            if (!observation_std_in.is_none())
              observation_std = vector_argument(observation_std_in, states_of(*simulator), "ResidualModel.fit", "observation_std");
            gp::BackendSettings settings;
            settings.exact_points = exact_points;
            settings.inducing = inducing;
            settings.frequencies = frequencies;
            std::unique_ptr<gp::GpBackend> made;
            try {
              made = gp::make_backend(backend, settings);
            } catch (const std::invalid_argument& e) {
              throw InputError(std::string("backend: ") + e.what());
            }
            gp::ResidualModelOptions options;
            options.fit.restarts = restarts;
            options.fit.max_evaluations = max_evaluations;
            options.fit.seed = seed;
            LongCall call;
            return call.run<std::shared_ptr<gp::ResidualModel>>([&] {
              gp::ResidualData residuals;
              try {
                residuals = gp::make_residual_data(*simulator, data);
              } catch (const std::invalid_argument& e) {  // the data's system or step differs from the simulator's
                throw InputError(fmt::format("ResidualModel.fit: {}", e.what()));
              }
              if (observation_std) {
                try {
                  options.noise_floor = gp::sensor_noise_floor(*simulator, residuals, *observation_std);
                } catch (const std::invalid_argument& e) {
                  throw InputError(std::string("observation_std: ") + e.what());
                }
              }
              return std::make_shared<gp::ResidualModel>(gp::ResidualModel::fit(simulator, residuals, *made, options));
            });
          },
          py::arg("simulator"), py::arg("data"), py::arg("backend") = "exact", py::arg("exact_points") = 300,
          py::arg("inducing") = 100, py::arg("frequencies") = 100, py::arg("restarts") = 1,
          py::arg("max_evaluations") = 150, py::arg("seed") = 1, py::arg("observation_std") = py::none(),
          R"(Fits one GP per state on the one-step errors of simulator (a StepModel at the data's dt) on
data (a MeasurementSet), with the backend's hyperparameters by NLopt. observation_std (one std per
state, optional): the sensors' noise; with the simulator's process noise it sets each GP's lowest
noise std (gp/noise_floor.hpp), so that the GP does not explain sensor noise as dynamics. Runs
without the GIL.)")
      .def("predict",
           [](const gp::ResidualModel& model, const py::object& x_in, const py::object& u_in) {
             const int n = model.state_dim(), mdim = model.control_dim();
             const std::string who = "ResidualModel.predict";
             const Matrix x = rows_argument(x_in, states_of(model), who, "x");
             const Matrix u = rows_argument(u_in, controls_of(model), who, "u");
             if (x.rows() != u.rows())
               raise_input_error(fmt::format("{}: x has {} rows and u {}; expected one row of u per row of x", who,
                                             x.rows(), u.rows()));
             Matrix z(x.rows(), n + mdim);
             z << x, u;
             Matrix mean(x.rows(), n), std(x.rows(), n);
             {
               py::gil_scoped_release release;
               Vector output_mean, output_variance;
               for (int i = 0; i < n; ++i) {
                 model.output(i).predict(z, output_mean, output_variance);
                 mean.col(i) = output_mean;
                 std.col(i) = output_variance.cwiseMax(0.0).cwiseSqrt();
               }
             }
             const std::string context = fmt::format("these finite x and u (the GP of {} is not finite there)",
                                                     step_model_label(model));
             require_finite_result(mean, who, "mean", context);
             require_finite_result(std, who, "std", context);
             return py::make_tuple(mean, std);
           },
           py::arg("x"), py::arg("u"),
           "The correction mu and its std at rows of x (N, n) and u (N, m): two arrays (N, n) [state units].")
      .def_property_readonly("hyperparameters", [](const gp::ResidualModel& model) {
        std::vector<Vector> out;
        for (int i = 0; i < model.state_dim(); ++i) out.push_back(model.output(i).parameters());
        return out;
      }, "per state: the log-space parameter vector [log l (n+m); log sf; log sn; backend extras]")
      .def_property_readonly("simulator", [](const gp::ResidualModel& model) {
        return std::const_pointer_cast<StepModel>(model.simulator_ptr());
      });
}

}  // namespace gpilqg::python
