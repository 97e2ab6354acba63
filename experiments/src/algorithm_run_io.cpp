#include "algorithm_run_io.hpp"

#include <limits>

#include <fmt/format.h>

#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/gp_io.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {
namespace {

constexpr const char* kModelGroup = "/model";

void write_gains(Hdf5Writer& h5, const std::string& path, const std::vector<Matrix>& gains) {
  const std::uint64_t m = gains.empty() ? 0 : static_cast<std::uint64_t>(gains.front().rows());
  const std::uint64_t n = gains.empty() ? 0 : static_cast<std::uint64_t>(gains.front().cols());
  std::vector<double> values;
  values.reserve(gains.size() * m * n);
  for (const Matrix& gain : gains) {
    const RowMajorMatrix rows = gain;
    values.insert(values.end(), rows.data(), rows.data() + rows.size());
  }
  h5.write_array(path, {gains.size(), m, n}, values);
}

std::vector<Matrix> read_gains(const Hdf5Reader& h5, const std::string& path) {
  const auto dims = h5.shape(path);
  if (dims.size() != 3) throw std::runtime_error(fmt::format("{}: dataset '{}' must be T x m x n", h5.file().string(), path));
  const std::vector<double> values = h5.read_array(path);
  const auto m = static_cast<Eigen::Index>(dims[1]), n = static_cast<Eigen::Index>(dims[2]);
  std::vector<Matrix> gains;
  for (std::uint64_t t = 0; t < dims[0]; ++t)
    gains.push_back(Eigen::Map<const RowMajorMatrix>(values.data() + t * dims[1] * dims[2], m, n));
  return gains;
}

/// A summary number that is +inf (a cost or gradient norm that was not finite: DdpSolver's merit and
/// gradient norm) is left out, so that a checkpoint holds finite numbers only; read_unbounded reads it back.
void write_unbounded(Hdf5Writer& h5, const std::string& path, double value) {
  if (value != std::numeric_limits<double>::infinity()) h5.write_scalar(path, value);
}

double read_unbounded(const Hdf5Reader& h5, const std::string& path) {
  return h5.exists(path) ? h5.read_scalar(path) : std::numeric_limits<double>::infinity();
}

void write_record(Hdf5Writer& h5, const std::string& g, const IterationRecord& r) {
  const AffinePolicy& p = r.plan.policy;
  h5.write_matrix(g + "/policy/x_bar", p.x_bar);
  h5.write_matrix(g + "/policy/u_bar", p.u_bar);
  h5.write_matrix(g + "/policy/k", p.k);
  write_gains(h5, g + "/policy/K", p.K);
  h5.write_vector(g + "/policy/u_min", p.u_min);
  h5.write_vector(g + "/policy/u_max", p.u_max);
  write_unbounded(h5, g + "/predicted_cost", r.plan.predicted_cost);
  h5.write_scalar(g + "/solve_seconds", r.plan.solve_seconds);
  h5.write_scalar(g + "/variant", static_cast<double>(r.plan.variant));
  const DdpSummary& s = r.plan.summary;
  h5.write_scalar(g + "/summary/termination", static_cast<double>(s.termination));
  h5.write_scalar(g + "/summary/iterations", s.iterations);
  write_unbounded(h5, g + "/summary/initial_cost", s.initial_cost);
  write_unbounded(h5, g + "/summary/final_cost", s.final_cost);
  write_unbounded(h5, g + "/summary/final_gradient_norm", s.final_gradient_norm);
  h5.write_scalar(g + "/summary/final_backward_failed", s.final_backward_failed ? 1.0 : 0.0);
  const Evaluation& e = r.evaluation;
  write_unbounded(h5, g + "/evaluation/mean_cost", e.mean_cost);
  h5.write_vector(g + "/evaluation/costs", e.costs);
  h5.write_matrix(g + "/evaluation/example_x", e.example.x);
  h5.write_matrix(g + "/evaluation/example_u", e.example.u);
  h5.write_scalar(g + "/evaluation/diverged", e.diverged);
  h5.write_scalar(g + "/evaluation/seconds", e.seconds);
  h5.write_scalar(g + "/data_rows", r.data_rows);
  h5.write_scalar(g + "/fit_seconds", r.fit_seconds);
  h5.write_scalar(g + "/rollout_seconds", r.rollout_seconds);
  write_unbounded(h5, g + "/policy_change", r.policy_change);
  h5.write_scalar(g + "/repeated", r.repeated ? 1.0 : 0.0);
  Matrix hyper(static_cast<Eigen::Index>(r.hyperparameters.size()),
               r.hyperparameters.empty() ? 0 : r.hyperparameters.front().size());
  for (std::size_t i = 0; i < r.hyperparameters.size(); ++i) hyper.row(static_cast<Eigen::Index>(i)) = r.hyperparameters[i].transpose();
  h5.write_matrix(g + "/hyperparameters", hyper);
  h5.write_vector(g + "/noise_floor", r.noise_floor);
}

int read_int(const Hdf5Reader& h5, const std::string& path) { return static_cast<int>(h5.read_scalar(path)); }

IterationRecord read_record(const Hdf5Reader& h5, const std::string& g) {
  IterationRecord r;
  AffinePolicy& p = r.plan.policy;
  p.x_bar = h5.read_matrix(g + "/policy/x_bar");
  p.u_bar = h5.read_matrix(g + "/policy/u_bar");
  p.k = h5.read_matrix(g + "/policy/k");
  p.K = read_gains(h5, g + "/policy/K");
  p.u_min = h5.read_vector(g + "/policy/u_min");
  p.u_max = h5.read_vector(g + "/policy/u_max");
  r.plan.predicted_cost = read_unbounded(h5, g + "/predicted_cost");
  r.plan.solve_seconds = h5.read_scalar(g + "/solve_seconds");
  r.plan.variant = static_cast<DdpVariant>(read_int(h5, g + "/variant"));
  DdpSummary& s = r.plan.summary;
  s.termination = static_cast<DdpTermination>(read_int(h5, g + "/summary/termination"));
  s.iterations = read_int(h5, g + "/summary/iterations");
  s.initial_cost = read_unbounded(h5, g + "/summary/initial_cost");
  s.final_cost = read_unbounded(h5, g + "/summary/final_cost");
  s.final_gradient_norm = read_unbounded(h5, g + "/summary/final_gradient_norm");
  s.final_backward_failed = h5.read_scalar(g + "/summary/final_backward_failed") != 0.0;
  Evaluation& e = r.evaluation;
  e.mean_cost = read_unbounded(h5, g + "/evaluation/mean_cost");
  const Vector costs = h5.read_vector(g + "/evaluation/costs");
  e.costs.assign(costs.data(), costs.data() + costs.size());
  e.example.x = h5.read_matrix(g + "/evaluation/example_x");
  e.example.u = h5.read_matrix(g + "/evaluation/example_u");
  e.diverged = read_int(h5, g + "/evaluation/diverged");
  e.seconds = h5.read_scalar(g + "/evaluation/seconds");
  r.data_rows = read_int(h5, g + "/data_rows");
  r.fit_seconds = h5.read_scalar(g + "/fit_seconds");
  r.rollout_seconds = h5.read_scalar(g + "/rollout_seconds");
  r.policy_change = read_unbounded(h5, g + "/policy_change");
  r.repeated = h5.read_scalar(g + "/repeated") != 0.0;
  const Matrix hyper = h5.read_matrix(g + "/hyperparameters");
  for (Eigen::Index i = 0; i < hyper.rows(); ++i) r.hyperparameters.push_back(hyper.row(i).transpose());
  r.noise_floor = h5.read_vector(g + "/noise_floor");
  return r;
}

}  // namespace

void write_algorithm_run(const std::filesystem::path& file, const AlgorithmRun& run) {
  {
    Hdf5Writer h5(file);
    h5.attribute("/", "name", run.name);
    h5.attribute("/", "converged_at", static_cast<std::int64_t>(run.converged_at));
    h5.attribute("/", "iterations", static_cast<std::int64_t>(run.iterations.size()));
    h5.write_matrix("/data/x", run.data.x);
    h5.write_matrix("/data/u", run.data.u);
    h5.write_matrix("/data/x_next", run.data.x_next);
    h5.write_vector("/data/iteration", run.data.iteration);
    for (std::size_t k = 0; k < run.iterations.size(); ++k) write_record(h5, fmt::format("/iter_{}", k), run.iterations[k]);
    if (const auto& d = run.diagnosis) {
      h5.write_scalar("/diagnosis/round", d->round);
      h5.write_scalar("/diagnosis/adopted", d->adopted ? 1.0 : 0.0);
      h5.write_scalar("/diagnosis/seconds", d->seconds);
      h5.write_scalar("/diagnosis/transitions", d->transitions);
      h5.attribute("/diagnosis/round", "verdict", d->verdict);
      h5.attribute("/diagnosis/round", "reason", d->reason);
      h5.attribute("/diagnosis/round", "model", diagnosis::model_file_text(d->model));
    }
    h5.close();
  }
  if (const auto* model = dynamic_cast<const gp::ResidualModel*>(run.final_model.get()))
    gp::save_residual_model(file, kModelGroup, *model);
}

AlgorithmRun read_algorithm_run(const std::filesystem::path& file, const std::string& system,
                                const SimulatorOf& simulator_of, const gp::BackendSettings& settings) {
  AlgorithmRun run;
  std::string backend;
  {
    const Hdf5Reader h5(file);
    run.name = h5.string_attribute("/", "name");
    run.converged_at = static_cast<int>(h5.number_attribute("/", "converged_at"));
    const int iterations = static_cast<int>(h5.number_attribute("/", "iterations"));
    run.data.x = h5.read_matrix("/data/x");
    run.data.u = h5.read_matrix("/data/u");
    run.data.x_next = h5.read_matrix("/data/x_next");
    const Vector iteration = h5.read_vector("/data/iteration");
    for (const double i : iteration) run.data.iteration.push_back(static_cast<int>(i));
    for (int k = 0; k < iterations; ++k) run.iterations.push_back(read_record(h5, fmt::format("/iter_{}", k)));
    if (h5.exists("/diagnosis/round")) {
      LoopDiagnosis d;
      d.round = static_cast<int>(h5.read_scalar("/diagnosis/round"));
      d.adopted = h5.read_scalar("/diagnosis/adopted") != 0.0;
      d.seconds = h5.read_scalar("/diagnosis/seconds");
      d.transitions = static_cast<int>(h5.read_scalar("/diagnosis/transitions"));
      d.verdict = h5.string_attribute("/diagnosis/round", "verdict");
      d.reason = h5.string_attribute("/diagnosis/round", "reason");
      d.model = diagnosis::parse_model_text(h5.string_attribute("/diagnosis/round", "model"),
                                            file.string() + ":/diagnosis/round attribute 'model'", system);
      d.changes = d.model.describe();
      run.diagnosis = std::move(d);
    }
    if (h5.exists(std::string(kModelGroup) + "/0")) backend = h5.string_attribute(std::string(kModelGroup) + "/0", "backend");
  }
  if (!backend.empty()) {
    const auto gp_backend = gp::make_backend(backend, settings);
    run.final_model = std::make_shared<const gp::ResidualModel>(
        gp::load_residual_model(file, kModelGroup, simulator_of(run.diagnosis), *gp_backend));
    if (!run.iterations.empty()) run.iterations.back().plan.model = run.final_model;
  }
  return run;
}

}  // namespace gpilqg
