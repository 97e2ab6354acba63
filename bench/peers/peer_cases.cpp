#include "peer_cases.hpp"

#include <string>
#include <vector>

#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "peer_timing.hpp"

namespace gpilqg::bench {

namespace {

using nlohmann::json;

std::vector<double> to_list(const Vector& v) { return {v.data(), v.data() + v.size()}; }

json timing_json(const RepeatedTiming& t) { return {{"best_s", t.best}, {"median_s", t.median}, {"times_s", t.seconds}}; }

gp::TrainingSet first_rows(const gp::TrainingSet& data, int n) {
  return gp::TrainingSet{data.inputs.topRows(n), data.targets.head(n)};
}

gp::ExactGpBackend exact_backend(int threads) {
  return gp::ExactGpBackend(gp::ExactGpOptions{gp::ExactGpOptions::kAllPoints, threads});
}

/// One timed NLML-with-gradient case on any backend's objective.
json objective_case(gp::MarginalLikelihoodObjective& objective, const Vector& theta, int repeats) {
  Vector gradient;
  gp::NlmlEvaluation e = objective.evaluate(theta, &gradient);  // untimed: sizes the workspace
  const RepeatedTiming t = time_repeated(repeats, [&] { e = objective.evaluate(theta, &gradient); });
  json out = timing_json(t);
  out["nlml"] = e.value;
  out["gradient"] = to_list(gradient);
  out["status"] = std::string(gp::to_string(e.status));
  out["jitter"] = e.jitter;
  return out;
}

}  // namespace

json nlml_case(const gp::TrainingSet& data, int n, const Vector& theta, int threads, int repeats) {
  const gp::TrainingSet subset = first_rows(data, n);
  auto objective = exact_backend(threads).objective(subset, gp::FitOptions{});
  json out = objective_case(*objective, theta, repeats);
  out["n"] = n;
  out["d"] = subset.input_dim();
  return out;
}

json fit_case(const gp::TrainingSet& data, int n, int threads, int repeats) {
  const gp::TrainingSet subset = first_rows(data, n);
  const gp::ExactGpBackend backend = exact_backend(threads);
  gp::FitOptions options;
  options.restarts = 0;  // one start: the data-driven initial values (no warm start given)
  // The start and the box the fitter uses (fit_parameters clips the start to the box), reported so
  // that the peer starts from the same point in the same box.
  const auto objective = backend.objective(subset, options);
  const gp::ParameterBounds box = objective->bounds();
  const Vector start = objective->initial_parameters().cwiseMax(box.lower).cwiseMin(box.upper);

  gp::FitResult fit;
  const RepeatedTiming t = time_repeated(repeats, [&] { fit = backend.fit(subset, options); });
  json out = timing_json(t);
  out["n"] = n;
  out["d"] = subset.input_dim();
  out["initial"] = to_list(start);
  out["lower"] = to_list(box.lower);
  out["upper"] = to_list(box.upper);
  out["max_evaluations"] = options.max_evaluations;
  out["relative_tolerance"] = options.relative_tolerance;
  out["parameter_tolerance"] = options.parameter_tolerance;
  out["theta"] = to_list(fit.model->parameters());
  out["nlml"] = fit.summary.nlml;
  out["initial_nlml"] = fit.summary.initial_nlml;
  out["evaluations"] = fit.summary.evaluations;
  out["termination"] = std::string(gp::to_string(fit.summary.termination));
  out["summary"] = fit.summary.one_line();
  return out;
}

json fitc_case(const gp::TrainingSet& data, const Vector& theta, int threads, int repeats) {
  gp::FitcOptions options;
  options.inducing = gp::FitcLayout::from_size(static_cast<int>(theta.size()), data.input_dim()).inducing;
  options.threads = threads;
  auto objective = gp::FitcBackend(options).objective(data, gp::FitOptions{});
  json out = objective_case(*objective, theta, repeats);
  out["n"] = data.size();
  out["d"] = data.input_dim();
  out["m"] = options.inducing;
  out["jitter_rule"] = "GPML: snu2 = 1e-6 sf2";
  return out;
}

json predict_case(const gp::TrainingSet& data, int n, const Vector& theta, const Matrix& points, int threads,
                  int repeats) {
  const auto model = exact_backend(threads).condition(first_rows(data, n), theta);
  Vector mean, variance;
  model->predict(points, mean, variance);  // untimed warm-up
  const RepeatedTiming t = time_repeated(repeats, [&] { model->predict(points, mean, variance); });
  json out = timing_json(t);
  out["n"] = n;
  out["d"] = data.input_dim();
  out["points"] = points.rows();
  out["conditioning"] = std::string(gp::to_string(model->conditioning().status));
  out["mean"] = to_list(mean);
  out["variance"] = to_list(variance);
  return out;
}

}  // namespace gpilqg::bench
