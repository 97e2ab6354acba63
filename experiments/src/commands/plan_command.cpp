/// `gpilqg plan CONFIG.toml [--data FILE]... [--previous POLICY.h5] --out POLICY.h5 [--seed S] [--json]`:
/// one round of Algorithm 1 on measurements from the real system (docs/real-robot.md).

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "commands.hpp"
#include "gpilqg/core/limits.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/planning.hpp"
#include "gpilqg/experiments/solve_config.hpp"

namespace gpilqg::cli {

namespace {

struct PlanOptions {
  std::string config;
  std::vector<std::string> data;
  std::string previous;
  std::string out;
  std::uint64_t seed = 1;
  bool json = false;
  bool diagnose = false;
  std::string write_model;
};

int run_plan(const PlanOptions& o) {
  std::vector<CommandInput> inputs = {{"CONFIG", o.config}, {"--previous", o.previous}};
  for (const auto& file : o.data) inputs.push_back({"--data", file});
  // The outputs against the files named on the command line, then, once the config is read, against
  // the files it names.
  const auto check_outputs = [&] {
    check_output_file_option("--out", o.out, {"plan writes an HDF5 policy file", kHdf5Extensions}, inputs);
    if (!o.write_model.empty())
      check_output_file_option("--write-model", o.write_model, {"plan writes a TOML model file", kTomlExtensions}, inputs);
  };
  check_outputs();
  if (!o.write_model.empty() && same_file(o.write_model, o.out))
    throw InputError("--write-model and --out name the same file; expected two files");
  PlanRequest request;
  request.config = read_plan_config(o.config);
  inputs.insert(inputs.end(), request.config.problem.files.begin(), request.config.problem.files.end());
  check_outputs();
  for (const auto& file : o.data) request.data_files.emplace_back(file);
  if (!o.previous.empty()) request.previous = o.previous;
  request.seed = o.seed;
  request.diagnose = o.diagnose;
  const PlannedPolicy planned = plan_policy(request);
  const DdpSummary& s = planned.summary;
  if (s.termination == DdpTermination::InitialRolloutDiverged) {
    Trajectory reached;  // the states before the divergence bound, the initial controls
    reached.x = planned.file.policy.x_bar;
    reached.u = planned.file.policy.u_bar;
    std::cerr << fmt::format("error: the initial controls {}; no policy was written to {}\n",
                             initial_rollout_failure(trajectory_cost(
                                 make_solve_cost(request.config.problem), reached)), o.out);
    return kExitInternalFailure;
  }
  write_policy_file(o.out, planned.file, planned.model.get());
  const auto& d = planned.diagnosis;
  // The model the round planned on, adopted or not: a scripted loop's next round plans on it, never on
  // a stale file left there before.
  const std::string data_text = fmt::format("{}", fmt::join(o.data, ", "));
  if (!o.write_model.empty() && d)
    diagnosis::write_model_file(o.write_model, planned.planned_on,
                                {d->adopted ? "diagnosed by `gpilqg plan --diagnose` on " + data_text
                                            : fmt::format("the config's simulator, kept by `gpilqg plan --diagnose` "
                                                          "(verdict {}) on {}", d->verdict, data_text)});
  if (o.json) {
    nlohmann::json out = policy_json(planned.file, planned.model.get());
    out["out"] = o.out;
    out["solver"] = {{"algorithm", std::string(to_string(planned.model ? request.config.problem.solver.variant : DdpVariant::ILQG))},
                     {"termination", std::string(to_string(s.termination))},
                     {"converged", converged(s.termination)},
                     {"iterations", s.iterations},
                     {"solve_time_s", s.timings.total_s},
                     {"start", planned.start}};
    out["data_rows"] = planned.data_rows;
    out["fit_time_s"] = planned.fit_seconds;
    out["gp_warm_start"] = planned.warm_started_gp;
    if (d)
      out["diagnosis"] = {{"verdict", d->verdict}, {"reason", d->reason}, {"adopted", d->adopted},
                          {"changes", d->changes}, {"transitions", d->transitions}, {"seconds", d->seconds},
                          {"model", d->adopted ? diagnosis::model_file_text(d->model) : std::string()},
                          {"model_file", o.write_model}};
    std::cout << out.dump() << '\n';
  } else {
    const PolicyFile& f = planned.file;
    if (d) {
      std::cout << "diagnosis: " << diagnosis_summary(*d) << '\n';
      if (d->adopted)
        std::cout << (o.write_model.empty() ? std::string("  planned on the diagnosed model (--write-model F.toml keeps it)\n")
                                            : fmt::format("  planned on the diagnosed model; wrote it to {}\n", o.write_model));
      else if (!o.write_model.empty())
        std::cout << fmt::format("  planned on the config's simulator (nothing adopted); wrote it to {} for the next "
                                 "round\n",
                                 o.write_model);
    }
    if (planned.model)
      std::cout << fmt::format("round {}: residual GP ({}) fitted on {} transitions from {} file(s) in {:.1f} s{}\n",
                               f.round, planned.model->output(0).backend_name(), planned.data_rows,
                               f.data_files.size(), planned.fit_seconds,
                               planned.warm_started_gp ? ", warm-started from --previous" : "");
    else
      std::cout << fmt::format("round {}: no data; planned on the simulator alone\n", f.round);
    std::cout << s.report(to_string(planned.model ? request.config.problem.solver.variant : DdpVariant::ILQG)) << '\n';
    if (planned.start != "the usual start")
      std::cout << fmt::format("started the solve from {}: it costs less on the model planned on than the usual start\n", planned.start);
    std::cout << fmt::format("predicted cost {:.6g}, expected cost {:.6g}; wrote {} (horizon {}, dt {} s)\n",
                             f.predicted_cost, f.expected_cost, o.out, f.policy.horizon(), f.dt);
  }
  if (!converged(s.termination))
    std::cerr << fmt::format("warning: the solver stopped without converging ({}); the policy is its last "
                             "iterate\n", to_string(s.termination));
  return kExitSuccess;
}

}  // namespace

void add_plan_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<PlanOptions>();
  auto* cmd = app.add_subcommand("plan", "One round of Algorithm 1 on measurements: fit the residual GP on the "
                                         "data files, solve with Robust-iLQG, write the policy file");
  cmd->add_option("CONFIG", o->config, "TOML: the `gpilqg solve` schema plus an optional [gp] table")->required();
  cmd->add_option("--data", o->data, "A measurement file (CSV or HDF5), repeatable, oldest first; the last holds "
                                     "the newest rollouts. None: plan on the simulator alone (round 0)");
  cmd->add_option("--previous", o->previous, "The previous round's policy file: warm start of the controls and "
                                             "of the GP, and the re-sample rule");
  cmd->add_option("--out", o->out, "The policy file to write (HDF5, docs/formats.md)")->required();
  cmd->add_option("--seed", o->seed, "Seed of the GP fit; equal seeds give the policies of `gpilqg run` with that seed")
      ->capture_default_str()
      ->check(integer_in(0, static_cast<long long>(limits::kMaxSeed)));
  cmd->add_flag("--diagnose", o->diagnose,
                "Diagnose the data first (`diagnose --auto` against the config's simulator); if the verdict is "
                "\"explained\", plan on the diagnosed model as the GP's mean");
  cmd->add_option("--write-model", o->write_model, "With --diagnose: write the diagnosed model file (TOML) for the "
                                                   "next round's [system] model")
      ->needs("--diagnose");
  cmd->add_flag("--json", o->json, "Print the policy file's content and the solver's summary as one JSON document");
  cmd->callback([&action, o] { action = [o] { return run_plan(*o); }; });
}

}  // namespace gpilqg::cli
