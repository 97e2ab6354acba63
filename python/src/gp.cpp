/// gpilqg.GaussianProcess: every GP backend of the library as one scikit-learn-like estimator
/// (gp_estimator.hpp does the work without the GIL, gp_arrays.hpp converts the arrays).

#include <cmath>
#include <optional>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "gp_arrays.hpp"
#include "gp_estimator.hpp"

namespace gpilqg::python {

namespace {

/// The Python object: a configuration and, after fit, the state it produced (shared, so a refit in
/// another thread never frees a model a running prediction or a view still reads).
struct GaussianProcess {
  GpConfig config;
  std::shared_ptr<const GpState> state;

  const GpState& fitted(const char* what) const {
    if (!state)
      throw std::runtime_error(std::string("GaussianProcess.") + what +
                               ": this GaussianProcess is not fitted yet; call fit(X, y) first");
    return *state;
  }
  std::shared_ptr<const GpState> fitted_state(const char* what) const {
    (void)fitted(what);
    return state;
  }
};

constexpr py::ssize_t kDouble = sizeof(double);

py::object fit(GaussianProcess& self, const py::object& self_object, const py::handle& X, const py::handle& y,
               const py::object& theta, const py::object& noise_variance) {
  const std::string who = "GaussianProcess.fit";
  const FortranArray inputs = checked_array(X, 2, who, "X", "(N, D)");
  const FortranArray targets = checked_array(y, 1, who, "y", "(N,)");
  if (targets.shape(0) != inputs.shape(0))
    raise_input_error(who + ": X has " + std::to_string(inputs.shape(0)) + " rows but y has " +
                     std::to_string(targets.shape(0)) + " entries");
  std::optional<Vector> parameters;
  if (!theta.is_none()) {
    const FortranArray t = checked_array(theta, 1, who, "theta", "(P,)");
    require_finite(t, who, "theta");
    parameters = Vector(as_vector(t));
  }
  gp::TrainingSet data{as_matrix(inputs), as_vector(targets)};  // the model owns its copy
  if (!noise_variance.is_none()) {
    const FortranArray v = checked_array(noise_variance, 1, who, "noise_variance", "(N,)");
    if (v.shape(0) != targets.shape(0))
      raise_input_error(who + ": noise_variance has " + std::to_string(v.shape(0)) + " entries but y has " +
                        std::to_string(targets.shape(0)));
    data.noise_variance = as_vector(v);
  }
  std::shared_ptr<const GpState> state;
  {
    py::gil_scoped_release release;
    state = fit_gp(self.config, std::move(data), parameters);
  }
  self.state = std::move(state);
  return self_object;
}

py::object predict(const GaussianProcess& self, const py::handle& X, bool return_std, bool return_grad) {
  const std::string who = "GaussianProcess.predict";
  const auto state = self.fitted_state("predict");
  const FortranArray inputs = checked_array(X, 2, who, "X", "(N, D)");
  require_finite(inputs, who, "X");
  const py::ssize_t n = inputs.shape(0);
  const py::ssize_t d = inputs.shape(1);
  if (d != state->model()->input_dim())
    raise_input_error(who + ": X has " + std::to_string(d) + " columns; the model was fitted to D = " +
                     std::to_string(state->model()->input_dim()));
  py::array_t<double> mean(n);
  std::optional<py::array_t<double>> std_dev, mean_gradient, std_gradient;
  PredictionBuffers out;
  out.mean = mean.mutable_data();
  if (return_std) out.std = std_dev.emplace(n).mutable_data();
  if (return_grad) {
    out.mean_gradient = mean_gradient.emplace(std::vector<py::ssize_t>{n, d}).mutable_data();
    if (return_std) out.std_gradient = std_gradient.emplace(std::vector<py::ssize_t>{n, d}).mutable_data();
  }
  {
    py::gil_scoped_release release;
    predict_gp(*state->model(), as_matrix(inputs), out);
  }
  if (!return_std && !return_grad) return mean;
  py::list results;
  results.append(mean);
  if (return_std) results.append(*std_dev);
  if (return_grad) results.append(*mean_gradient);
  if (return_grad && return_std) results.append(*std_gradient);
  return py::tuple(results);
}

py::object log_marginal_likelihood(const GaussianProcess& self, const py::object& theta, bool eval_gradient) {
  const std::string who = "GaussianProcess.log_marginal_likelihood";
  const auto state = self.fitted_state("log_marginal_likelihood");
  Vector parameters = state->model()->parameters();
  if (!theta.is_none()) {
    const FortranArray t = checked_array(theta, 1, who, "theta", "(P,)");
    require_finite(t, who, "theta");
    parameters = as_vector(t);
  }
  Vector gradient;
  double value = 0.0;
  {
    py::gil_scoped_release release;
    value = state->log_marginal_likelihood(parameters, eval_gradient ? &gradient : nullptr);
  }
  if (!eval_gradient) return py::float_(value);
  py::array_t<double> g(gradient.size());
  Eigen::Map<Vector>(g.mutable_data(), gradient.size()) = gradient;
  return py::make_tuple(value, g);
}

/// theta_ and the views into it: the model's parameter vector is contiguous, the extras are a
/// column-major block of it (entry (r, d) at D + 2 + d * rows + r).
py::array theta_view(const GpState& state) {
  const Vector& theta = state.model()->parameters();
  return model_view(state.model(), theta.data(), {static_cast<py::ssize_t>(theta.size())}, {kDouble});
}

py::array extras_view(const GpState& state, const char* backend, const char* attribute) {
  if (state.model()->backend_name() != backend)
    throw py::attribute_error(std::string("GaussianProcess.") + attribute + " exists for the " + backend +
                              " backend only; this model is " + std::string(state.model()->backend_name()));
  const int d = state.model()->input_dim();
  const py::ssize_t rows = state.extra_rows();
  const double* start = state.model()->parameters().data() + gp::Hyperparameters::count(d);
  return model_view(state.model(), start, {rows, d}, {kDouble, rows * kDouble});
}

py::dict summary_dict(const gp::FitSummary& s) {
  py::dict out;
  out["backend"] = s.backend;
  out["training_points"] = s.training_points;
  out["parameters"] = s.parameters;
  out["initial_log_marginal_likelihood"] = -s.initial_nlml;
  out["log_marginal_likelihood"] = -s.nlml;
  out["starts"] = s.starts;
  out["best_start"] = s.best_start;
  out["evaluations"] = s.evaluations;
  out["jittered_evaluations"] = s.jittered_evaluations;
  out["failed_evaluations"] = s.failed_evaluations;
  out["max_jitter"] = s.max_jitter;
  out["termination"] = std::string(gp::to_string(s.termination));
  out["seconds"] = s.seconds;
  out["text"] = s.one_line();
  return out;
}

}  // namespace

void bind_gp(py::module_& m) {
  m.attr("gp_backends") = gp::backend_names();

  py::class_<GaussianProcess> cls(m, "GaussianProcess", R"doc(
Gaussian process regression with one of the library's GP backends (scikit-learn-like estimator).

Every backend is a zero-mean GP on the targets with hyperparameters in log space,

    theta = [log l_1 .. log l_D, log sf, log sn, backend extras]   (shape (P,))

(l: length-scales, sf: signal standard deviation, sn: noise standard deviation). Backends
(``gpilqg.gp_backends``):

- ``"exact"``: squared exponential ARD kernel sf^2 exp(-0.5 sum_d (a_d - b_d)^2 / l_d^2), exact GP on
  a uniform subsample of ``exact_points`` training points.
- ``"fitc"``: FITC sparse GP with the same kernel and M = ``inducing`` pseudo-inputs; extras: the
  pseudo-inputs (M, D), column-major, optimised with the hyperparameters.
- ``"ssgp"``: sparse spectrum GP, Bayesian linear regression on the 2m features
  [cos(S x); sin(S x)] with S = W / l and weights ~ N(0, sf^2 / m); extras: the m = ``frequencies``
  unscaled spectral points W (m, D), column-major.
- ``"compact"``: exact GP with Wendland's compactly supported kernel
  sf^2 (1 - r)_+^(j+1) ((j+1) r + 1), r^2 = sum_d (a_d - b_d)^2 / l_d^2, j = floor(D/2) + 2
  (l_d is the support radius); sparse Cholesky on all points.

Predictions are of the latent function f (noise-free): add ``noise_std_**2`` to the variance for a
new observation. fit() copies X and y once (the model owns its training set); the fitted parameters
and training points are read-only views of the model, not copies.
)doc");

  cls.def(py::init([](const std::string& backend, int exact_points, int inducing, int frequencies,
                      int compact_neighbours, int compact_max_neighbours, int restarts, int max_evaluations,
                      std::uint64_t seed, int threads) {
            GaussianProcess estimator;
            estimator.config.backend = backend;
            estimator.config.settings.exact_points = exact_points;
            estimator.config.settings.inducing = inducing;
            estimator.config.settings.frequencies = frequencies;
            estimator.config.settings.compact_neighbours = compact_neighbours;
            estimator.config.settings.compact_max_neighbours = compact_max_neighbours;
            estimator.config.settings.threads = threads;
            estimator.config.fit.restarts = restarts;
            estimator.config.fit.max_evaluations = max_evaluations;
            estimator.config.fit.seed = seed;
            estimator.config.validate();
            return estimator;
          }),
          py::arg("backend") = "exact", py::kw_only(), py::arg("exact_points") = 300, py::arg("inducing") = 100,
          py::arg("frequencies") = 100, py::arg("compact_neighbours") = 32, py::arg("compact_max_neighbours") = 256,
          py::arg("restarts") = 1, py::arg("max_evaluations") = 150, py::arg("seed") = 1, py::arg("threads") = 1,
          R"doc(
Parameters
----------
backend : str
    "exact", "fitc", "ssgp" or "compact".
exact_points : int
    "exact": size of the uniform subsample of the training data (all points when N <= exact_points).
inducing : int
    "fitc": number M of pseudo-inputs (min(M, N) are used).
frequencies : int
    "ssgp": number m of spectral points (2m features).
compact_neighbours, compact_max_neighbours : int
    "compact": neighbours per point at the data-driven start, and the cap on the support radii.
restarts : int
    Random restarts of the optimiser besides the data-driven start.
max_evaluations : int
    NLML evaluations per start (NLopt L-BFGS).
seed : int
    Seed for the subsample, the initial extras and the restarts.
threads : int
    Threads inside one NLML evaluation.

Raises ValueError (the library's message) for an unknown backend or a bad setting.
)doc");

  cls.def(
      "fit",
      [](py::object self_object, const py::object& X, const py::object& y, const py::object& theta,
         const py::object& noise_variance) {
        return fit(self_object.cast<GaussianProcess&>(), self_object, X, y, theta, noise_variance);
      },
      py::arg("X"), py::arg("y"), py::arg("theta") = py::none(), py::arg("noise_variance") = py::none(), R"doc(
Fit the hyperparameters by maximising the log marginal likelihood (NLopt L-BFGS with restarts), or,
with ``theta``, condition on the data with the given hyperparameters as they are (no optimisation).

Parameters
----------
X : array of shape (N, D)
    Training inputs, one point per row (copied once into the model).
y : array of shape (N,)
    Training targets.
theta : array of shape (P,), optional
    [log l (D); log sf; log sn; extras]: FITC's pseudo-inputs (M, D) or SSGP's spectral points
    (m, D), flattened column-major (``Z.ravel(order="F")``); their number is read from P.
noise_variance : array of shape (N,), optional
    A noise variance of each target known before the fit, v_i >= 0: the likelihood is
    y ~ N(0, K + diag(sn^2 + v_i)) with sn learned (scikit-learn's per-sample ``alpha`` with a
    ``WhiteKernel``). A backend that does not take it raises ValueError naming those that do; the
    predictions' std stays the latent one.

The model is conditioned on the points the backend selects (exact: a uniform subsample of
``exact_points`` drawn with ``seed``; ``X_train_`` shows them). Returns self. The GIL is released
during the fit (Ctrl-C takes effect when it returns). Raises ValueError (the library's message) for
degenerate data (non-finite entries, constant targets, N < D) or a wrongly sized theta,
gpilqg.InputError for wrong shapes, RuntimeError when the covariance cannot be factorised even with
jitter.
)doc");

  cls.def(
      "predict",
      [](const GaussianProcess& self, const py::object& X, bool return_std, bool return_grad) {
        return predict(self, X, return_std, return_grad);
      },
      py::arg("X"), py::arg("return_std") = false, py::arg("return_grad") = false, R"doc(
Latent predictive mean, and optionally standard deviation and input gradients.

Parameters
----------
X : array of shape (N, D)
    Test inputs, one per row (read in place when Fortran-ordered float64, else converted once).
return_std : bool
    Also return the latent standard deviation (without the observation noise).
return_grad : bool
    Also return the gradients with respect to the test input.

Returns
-------
mean : array of shape (N,)
    Alone when neither flag is set; otherwise a tuple in the order below.
std : array of shape (N,), if return_std
    sqrt of the latent variance.
mean_grad : array of shape (N, D), if return_grad
    d mean_i / d X[i, d].
std_grad : array of shape (N, D), if return_grad and return_std
    d std_i / d X[i, d] = (d variance_i / d X[i, d]) / (2 std_i); 0 where std_i = 0.

The GIL is released during the prediction. Raises RuntimeError before fit, gpilqg.InputError for a
wrong shape or a non-finite input.
)doc");

  cls.def(
      "log_marginal_likelihood",
      [](const GaussianProcess& self, const py::object& theta, bool eval_gradient) {
        return log_marginal_likelihood(self, theta, eval_gradient);
      },
      py::arg("theta") = py::none(), py::arg("eval_gradient") = false, R"doc(
Log marginal likelihood log p(y | X, theta) of the model's training points (as in scikit-learn).

Parameters
----------
theta : array of shape (P,), optional
    Log-space parameter vector (see the class); default the fitted ``theta_``.
eval_gradient : bool
    Also return the gradient with respect to theta.

Returns
-------
lml : float
    The library minimises nlml = -lml; this is -nlml. -inf when the covariance cannot be factorised.
lml_gradient : array of shape (P,), if eval_gradient
    d lml / d theta (zero when lml is -inf).
)doc");

  cls.def(
      "get_params",
      [](const GaussianProcess& self, bool /*deep*/) {
        const GpConfig& c = self.config;
        py::dict params;
        params["backend"] = c.backend;
        params["exact_points"] = c.settings.exact_points;
        params["inducing"] = c.settings.inducing;
        params["frequencies"] = c.settings.frequencies;
        params["compact_neighbours"] = c.settings.compact_neighbours;
        params["compact_max_neighbours"] = c.settings.compact_max_neighbours;
        params["restarts"] = c.fit.restarts;
        params["max_evaluations"] = c.fit.max_evaluations;
        params["seed"] = c.fit.seed;
        params["threads"] = c.settings.threads;
        return params;
      },
      py::arg("deep") = true, "The constructor's arguments as a dict (scikit-learn convention).");

  cls.def("__repr__", [](const GaussianProcess& self) {
    return "GaussianProcess(backend='" + self.config.backend + "'" + (self.state ? ", fitted)" : ")");
  });

  cls.def_property_readonly(
      "backend_", [](const GaussianProcess& self) { return std::string(self.fitted("backend_").model()->backend_name()); },
      "Name of the backend the model was fitted with (str).");
  cls.def_property_readonly(
      "n_features_in_", [](const GaussianProcess& self) { return self.fitted("n_features_in_").model()->input_dim(); },
      "Input dimension D seen in fit (int).");
  cls.def_property_readonly(
      "theta_", [](const GaussianProcess& self) { return theta_view(self.fitted("theta_")); },
      "Fitted log-space parameter vector [log l (D); log sf; log sn; extras], shape (P,); a read-only view "
      "of the model's memory.");
  cls.def_property_readonly(
      "length_scales_",
      [](const GaussianProcess& self) {
        const Vector l = self.fitted("length_scales_").model()->hyperparameters().lengthscales();
        py::array_t<double> out(l.size());
        Eigen::Map<Vector>(out.mutable_data(), l.size()) = l;
        return out;
      },
      "Length-scales l = exp(theta_[:D]), shape (D,), in input units (a new array: the model stores logs).");
  cls.def_property_readonly(
      "signal_std_",
      [](const GaussianProcess& self) {
        return std::sqrt(self.fitted("signal_std_").model()->prior_variance());
      },
      "Signal standard deviation sf (float, target units): the latent std far from all data.");
  cls.def_property_readonly(
      "noise_std_",
      [](const GaussianProcess& self) { return std::sqrt(self.fitted("noise_std_").model()->noise_variance()); },
      "Observation noise standard deviation sn (float, target units).");
  cls.def_property_readonly(
      "inducing_inputs_",
      [](const GaussianProcess& self) { return extras_view(self.fitted("inducing_inputs_"), "fitc", "inducing_inputs_"); },
      "FITC pseudo-inputs, shape (M, D), input units; a read-only view into theta_ (AttributeError for other "
      "backends).");
  cls.def_property_readonly(
      "spectral_points_",
      [](const GaussianProcess& self) { return extras_view(self.fitted("spectral_points_"), "ssgp", "spectral_points_"); },
      "SSGP unscaled spectral points W, shape (m, D); the frequencies are W / length_scales_. A read-only view "
      "into theta_ (AttributeError for other backends).");
  cls.def_property_readonly(
      "X_train_",
      [](const GaussianProcess& self) {
        const auto& state = self.fitted("X_train_");
        const Matrix& x = state.model()->training_set().inputs;
        return model_view(state.model(), x.data(), {x.rows(), x.cols()}, {kDouble, x.rows() * kDouble});
      },
      "Inputs the model is conditioned on, shape (N_train, D) (exact: the subsample); a read-only view of the "
      "model's memory.");
  cls.def_property_readonly(
      "y_train_",
      [](const GaussianProcess& self) {
        const auto& state = self.fitted("y_train_");
        const Vector& y = state.model()->training_set().targets;
        return model_view(state.model(), y.data(), {y.size()}, {kDouble});
      },
      "Targets the model is conditioned on, shape (N_train,); a read-only view of the model's memory.");
  cls.def_property_readonly(
      "conditioning_status_",
      [](const GaussianProcess& self) {
        return std::string(gp::to_string(self.fitted("conditioning_status_").model()->conditioning().status));
      },
      "How the covariance factorisation went: \"ok\" or \"jitter added\" (a failure raises in fit).");
  cls.def_property_readonly(
      "jitter_", [](const GaussianProcess& self) { return self.fitted("jitter_").model()->conditioning().jitter; },
      "Absolute jitter added to the covariance diagonal when conditioning (float, 0 when status is \"ok\").");
  cls.def_property_readonly(
      "log_marginal_likelihood_value_",
      [](const GaussianProcess& self) {
        return -self.fitted("log_marginal_likelihood_value_").model()->negative_log_marginal_likelihood();
      },
      "Log marginal likelihood at theta_ (float).");
  cls.def_property_readonly(
      "fit_summary_", [](const GaussianProcess& self) { return summary_dict(self.fitted("fit_summary_").summary()); },
      "The fit as a dict: evaluations, starts, termination (\"converged\", \"not optimised\", ...), jittered "
      "and failed evaluations, initial and final log marginal likelihood, seconds, and 'text' (one line).");
}

}  // namespace gpilqg::python
