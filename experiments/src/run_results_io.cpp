#include "gpilqg/experiments/run_results_io.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <ctime>

#include <fmt/format.h>

#include "gpilqg/experiments/diagnosis/model_file.hpp"

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/core/utc_time.hpp"
#include "gpilqg/core/version.hpp"
#include "gpilqg/experiments/model_slice_io.hpp"
#include "gpilqg/experiments/normalised_cost.hpp"

namespace gpilqg {
namespace {

/// <group>/{diagnosed_from, diagnosis_round} (S) and their per-seed texts, when a seed's run has a
/// diagnosis inside the loop (loop_diagnosis.hpp).
void write_loop_diagnosis(Hdf5Writer& h5, const std::string& group, const TaskResults& task, std::size_t a) {
  bool any = false;
  for (const auto& seed_runs : task.seeds) any = any || seed_runs[a].diagnosis.has_value();
  if (!any) return;
  std::vector<double> from, round;
  std::vector<std::string> summary, model;
  for (const auto& seed_runs : task.seeds) {
    const auto& d = seed_runs[a].diagnosis;
    from.push_back(diagnosed_from(d));
    round.push_back(d ? d->round : -1);
    summary.push_back(d ? diagnosis_summary(*d) : std::string());
    model.push_back(d && d->adopted ? diagnosis::model_file_text(d->model) : std::string());
  }
  h5.write_vector(group + "/diagnosed_from", from);
  h5.write_vector(group + "/diagnosis_round", round);
  h5.attribute(group + "/diagnosed_from", "diagnosis", summary);
  h5.attribute(group + "/diagnosed_from", "model", model);
}

using u64 = std::uint64_t;

/// (K+1 x S) from a value per (iteration, seed).
template <class Value>
Matrix per_iteration_and_seed(const TaskResults& task, std::size_t a, Value&& value) {
  const auto& first = task.seeds.front()[a];
  Matrix out(static_cast<Eigen::Index>(first.iterations.size()), static_cast<Eigen::Index>(task.seeds.size()));
  for (std::size_t s = 0; s < task.seeds.size(); ++s)
    for (std::size_t k = 0; k < first.iterations.size(); ++k)
      out(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(s)) = value(task.seeds[s][a].iterations[k]);
  return out;
}

/// Appends a matrix in row-major order.
void append_rows(std::vector<double>& out, const Matrix& m) {
  const RowMajorMatrix r = m;
  out.insert(out.end(), r.data(), r.data() + r.size());
}

void write_algorithm(Hdf5Writer& h5, const std::string& group, const TaskResults& task, std::size_t a,
                     std::size_t reference, const std::vector<std::string>& state_names) {
  const std::size_t S = task.seeds.size();
  const auto& first = task.seeds.front()[a];
  const std::size_t iterations = first.iterations.size();
  const Matrix cost = per_iteration_and_seed(task, a, [](const IterationRecord& r) { return r.evaluation.mean_cost; });
  h5.write_matrix(group + "/cost", cost);
  Matrix normalised(cost.rows(), cost.cols()), standard_error(cost.rows(), cost.cols());
  for (Eigen::Index k = 0; k < cost.rows(); ++k)
    for (Eigen::Index s = 0; s < cost.cols(); ++s) {
      const auto& seed_runs = task.seeds[static_cast<std::size_t>(s)];
      const auto& record = seed_runs[a].iterations[static_cast<std::size_t>(k)];
      const auto& reference_record = seed_runs[reference].iterations[static_cast<std::size_t>(k)];
      const NormalisedCost c = normalised_cost(record.evaluation.costs, reference_record.evaluation.costs);
      normalised(k, s) = c.value;
      standard_error(k, s) = c.standard_error;
    }
  h5.write_matrix(group + "/normalised_cost", normalised);
  h5.write_matrix(group + "/normalised_cost_se", standard_error);
  h5.write_matrix(group + "/time_fit", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return r.fit_seconds; }));
  h5.write_matrix(group + "/time_solve", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return r.plan.solve_seconds; }));
  h5.write_matrix(group + "/time_rollouts", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return r.rollout_seconds; }));
  h5.write_matrix(group + "/time_evaluation", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return r.evaluation.seconds; }));
  h5.write_matrix(group + "/data_rows", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return double(r.data_rows); }));
  h5.write_matrix(group + "/repeated", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return r.repeated ? 1.0 : 0.0; }));
  h5.write_matrix(group + "/diverged", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return double(r.evaluation.diverged); }));
  h5.write_matrix(group + "/policy_change", per_iteration_and_seed(task, a, [](const IterationRecord& r) { return r.policy_change; }));
  std::vector<double> converged;
  for (std::size_t s = 0; s < S; ++s) converged.push_back(task.seeds[s][a].converged_at);
  h5.write_vector(group + "/converged_at", converged);
  write_loop_diagnosis(h5, group, task, a);

  const std::size_t E = first.iterations.front().evaluation.costs.size();
  std::vector<double> evaluation_costs;
  for (std::size_t k = 0; k < iterations; ++k)
    for (std::size_t s = 0; s < S; ++s) {
      const auto& costs = task.seeds[s][a].iterations[k].evaluation.costs;
      evaluation_costs.insert(evaluation_costs.end(), costs.begin(), costs.end());
    }
  h5.write_array(group + "/evaluation_costs", {u64(iterations), u64(S), u64(E)}, evaluation_costs);

  for (std::size_t k = 0; k < iterations; ++k) {
    const std::string it = fmt::format("{}/iter_{}", group, k);
    const auto& p0 = first.iterations[k].plan.policy;
    const u64 n = u64(p0.x_bar.rows()), m = u64(p0.u_bar.rows()), T = u64(p0.u_bar.cols());
    std::vector<double> x, u, K, kff, ex, eu, predicted, solve;
    for (std::size_t s = 0; s < S; ++s) {
      const IterationRecord& r = task.seeds[s][a].iterations[k];
      append_rows(x, r.plan.policy.x_bar);
      append_rows(u, r.plan.policy.u_bar);
      append_rows(kff, r.plan.policy.k);
      for (const Matrix& gain : r.plan.policy.K) append_rows(K, gain);
      append_rows(ex, r.evaluation.example.x);
      append_rows(eu, r.evaluation.example.u);
      predicted.push_back(r.plan.predicted_cost);
      solve.push_back(r.plan.solve_seconds);
    }
    h5.write_array(it + "/x", {u64(S), n, T + 1}, x);
    h5.write_array(it + "/u", {u64(S), m, T}, u);
    h5.write_array(it + "/K", {u64(S), T, m, n}, K);
    h5.write_array(it + "/k", {u64(S), m, T}, kff);
    h5.write_array(it + "/eval_x", {u64(S), n, T + 1}, ex);
    h5.write_array(it + "/eval_u", {u64(S), m, T}, eu);
    h5.write_vector(it + "/predicted_cost", predicted);
    h5.write_vector(it + "/solve_time", solve);
  }

  bool any_gp = false;
  for (const auto& record : first.iterations) any_gp = any_gp || !record.hyperparameters.empty();
  if (!any_gp) return;
  for (std::size_t i = 0; i < state_names.size(); ++i) {
    std::size_t P = 0;
    for (const auto& seed_runs : task.seeds)
      for (const auto& record : seed_runs[a].iterations)
        if (!record.hyperparameters.empty()) P = u64(record.hyperparameters[i].size());
    std::vector<double> hyper;
    Matrix fitted(static_cast<Eigen::Index>(iterations), static_cast<Eigen::Index>(S));
    Matrix floor = Matrix::Zero(static_cast<Eigen::Index>(iterations), static_cast<Eigen::Index>(S));
    for (std::size_t k = 0; k < iterations; ++k)
      for (std::size_t s = 0; s < S; ++s) {
        const auto& record = task.seeds[s][a].iterations[k];
        const bool has = !record.hyperparameters.empty();
        fitted(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(s)) = has ? 1.0 : 0.0;
        if (has && record.noise_floor.size() != 0)
          floor(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(s)) = record.noise_floor(static_cast<Eigen::Index>(i));
        for (std::size_t j = 0; j < P; ++j)
          hyper.push_back(has ? record.hyperparameters[i](static_cast<Eigen::Index>(j)) : 0.0);
      }
    const std::string g = group + "/gp/" + state_names[i];
    h5.write_array(g + "/hyper", {u64(iterations), u64(S), u64(P)}, hyper);
    h5.write_matrix(g + "/fitted", fitted);
    h5.write_matrix(g + "/noise_floor", floor);
  }
}

void write_data(Hdf5Writer& h5, const std::string& group, const TaskResults& task, std::size_t a,
                const std::vector<std::uint64_t>& seeds) {
  std::vector<const TransitionData*> parts;
  Eigen::Index rows = 0;
  for (const auto& seed_runs : task.seeds) {
    parts.push_back(&seed_runs[a].data);
    rows += seed_runs[a].data.size();
  }
  const Eigen::Index n = task.seeds.front()[a].data.x.cols(), m = task.seeds.front()[a].data.u.cols();
  Matrix x(rows, n), u(rows, m), dx(rows, n);
  std::vector<double> seed_of_row, iteration_of_row;
  Eigen::Index row = 0;
  for (std::size_t s = 0; s < parts.size(); ++s) {
    const TransitionData& d = *parts[s];
    if (d.size() == 0) continue;
    x.middleRows(row, d.size()) = d.x;
    u.middleRows(row, d.size()) = d.u;
    dx.middleRows(row, d.size()) = d.x_next - d.x;
    row += d.size();
    seed_of_row.insert(seed_of_row.end(), static_cast<std::size_t>(d.size()), static_cast<double>(seeds[s]));
    iteration_of_row.insert(iteration_of_row.end(), d.iteration.begin(), d.iteration.end());
  }
  h5.write_matrix(group + "/data/x", x);
  h5.write_matrix(group + "/data/u", u);
  h5.write_matrix(group + "/data/dx", dx);
  h5.write_vector(group + "/data/seed", seed_of_row);
  h5.write_vector(group + "/data/iteration", iteration_of_row);
}

std::size_t index_of(const std::vector<std::string>& names, const std::string& name) {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return i;
  throw std::logic_error("run results: no algorithm '" + name + "'");
}

}  // namespace

void write_run_results_to(Hdf5Writer& h5, const std::string& root, const RunResults& results) {
  const std::string here = root.empty() ? "/" : root;
  const RunConfig& c = results.config;
  const SystemSignature signature = system_signature(c.system);
  std::vector<std::string> state_names;
  for (const auto& q : signature.states) state_names.push_back(q.name);

  h5.attribute(here, "schema_version", kRunResultsSchemaVersion);
  h5.attribute(here, "gpilqg_version", std::string(kVersionString));
  h5.attribute(here, "config", c.text);
  h5.attribute(here, "model_files", c.files_text);
  h5.attribute(here, "seed", static_cast<std::int64_t>(results.options.seeds.front()));
  h5.attribute(here, "created", utc_timestamp());
  h5.attribute(here, "system", c.system);
  std::vector<double> seeds(results.options.seeds.begin(), results.options.seeds.end());
  h5.write_vector(root + "/seeds", seeds);

  for (std::size_t t = 0; t < c.tasks.size(); ++t) {
    const TaskResults& task = results.tasks[t];
    const std::string group = root + "/" + c.tasks[t].name;
    h5.attribute(group, "algorithms", task.algorithms);
    h5.attribute(group, "transfer", std::int64_t{c.tasks[t].transfer ? 1 : 0});
    h5.attribute(group, "horizon", std::int64_t{c.tasks[t].horizon});
    h5.attribute(group, "dt", c.dt);
    const std::size_t reference = index_of(task.algorithms, "ilqg_real");
    const bool compared = !results.options.backends.empty();
    const std::string main_gp = compared ? "gp_ilqg_" + results.options.backends.front() : "gp_ilqg";
    write_data(h5, group, task, index_of(task.algorithms, main_gp), results.options.seeds);
    for (std::size_t a = 0; a < task.algorithms.size(); ++a)
      write_algorithm(h5, group + "/" + task.algorithms[a], task, a, reference, state_names);
    if (compared) h5.link(group + "/gp_ilqg", group + "/" + main_gp);
    write_model_slice(h5, group, task.slice, signature);
  }
}

namespace {

/// The per-iteration matrices (K+1 x S) of an algorithm's group.
constexpr std::array<std::string_view, 11> kIterationBySeed = {
    "cost", "normalised_cost", "normalised_cost_se", "time_fit", "time_solve", "time_rollouts", "time_evaluation",
    "data_rows", "repeated", "diverged", "policy_change"};
/// The datasets of an algorithm's iter_<k>/ group (S x ...).
constexpr std::array<std::string_view, 8> kPlanBySeed = {"x", "u", "K", "k", "eval_x", "eval_u", "predicted_cost", "solve_time"};

bool is_one_of(std::string_view name, const auto& names) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

/// "iter_<k>/<leaf>" -> "<leaf>"; empty when `dataset` is not in an iter_<k> group.
std::string_view iteration_leaf(std::string_view dataset) {
  constexpr std::string_view prefix = "iter_";
  if (dataset.substr(0, prefix.size()) != prefix) return {};
  const std::size_t slash = dataset.find('/');
  const std::string_view k = dataset.substr(prefix.size(), slash == std::string_view::npos ? 0 : slash - prefix.size());
  if (k.empty() || !std::all_of(k.begin(), k.end(), [](char c) { return c >= '0' && c <= '9'; })) return {};
  return dataset.substr(slash + 1);
}

/// "gp/<state>/<leaf>" -> "<leaf>"; empty when `dataset` is not in a gp/<state> group.
std::string_view gp_leaf(std::string_view dataset) {
  constexpr std::string_view prefix = "gp/";
  if (dataset.substr(0, prefix.size()) != prefix) return {};
  const std::size_t slash = dataset.find('/', prefix.size());
  if (slash == std::string_view::npos || slash == prefix.size()) return {};
  return dataset.substr(slash + 1);
}

}  // namespace

std::optional<std::size_t> seed_axis(std::string_view dataset) {
  if (is_one_of(dataset, kIterationBySeed) || dataset == "evaluation_costs") return 1;
  if (dataset == "converged_at" || dataset == "diagnosed_from" || dataset == "diagnosis_round") return 0;
  if (is_one_of(iteration_leaf(dataset), kPlanBySeed)) return 0;
  const std::string_view gp = gp_leaf(dataset);
  if (gp == "hyper" || gp == "fitted" || gp == "noise_floor") return 1;
  return std::nullopt;
}

bool is_wall_clock_time(std::string_view dataset) {
  return dataset == "time_fit" || dataset == "time_solve" || dataset == "time_rollouts" || dataset == "time_evaluation" ||
         iteration_leaf(dataset) == "solve_time";
}

void write_run_results(const std::filesystem::path& file, const RunResults& results) {
  write_atomically(file, [&](const std::filesystem::path& temporary) {
    Hdf5Writer h5(temporary);
    write_run_results_to(h5, "", results);
    h5.close();
  });
}

}  // namespace gpilqg
