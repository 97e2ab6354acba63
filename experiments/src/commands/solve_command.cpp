/// `gpilqg solve CONFIG.toml [--json]`: one trajectory-optimisation problem from a TOML file.

#include <cmath>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/solve_config.hpp"

namespace gpilqg::cli {

namespace {

std::vector<double> as_list(const VectorCRef& v) { return {v.data(), v.data() + v.size()}; }

int run_solve(const std::string& file, bool json) {
  const SolveConfig config = read_solve_config(file);
  SolvedConfig solved = solve_config(config);
  DdpResult& r = solved.result;
  if (!std::isfinite(r.nominal_cost) || !std::isfinite(r.expected_cost)) {
    // The initial rollout diverged (costs +infinity): scored like a diverged rollout, the cost of the
    // states reached with the last one repeated (trajectory.hpp); the termination says why.
    r.nominal_cost = r.expected_cost = trajectory_cost(make_solve_cost(config), r.trajectory);
    r.summary.initial_cost = r.summary.final_cost = r.nominal_cost;
  }
  const auto& s = r.summary;
  const Vector x_final = r.trajectory.x.col(r.trajectory.x.cols() - 1);
  if (json) {
    nlohmann::json out;
    out["cost"] = r.nominal_cost;
    out["expected_cost"] = r.expected_cost;
    out["iterations"] = s.iterations;
    out["termination"] = std::string(to_string(s.termination));
    out["converged"] = converged(s.termination);
    if (std::isfinite(s.final_gradient_norm)) out["gradient_norm"] = s.final_gradient_norm;  // absent: not finite
    out["x_final"] = as_list(x_final);
    nlohmann::json u = nlohmann::json::array();
    for (Eigen::Index t = 0; t < r.trajectory.u.cols(); ++t) u.push_back(as_list(r.trajectory.u.col(t)));
    out["u"] = u;
    out["solve_time_s"] = s.timings.total_s;
    out["algorithm"] = std::string(to_string(config.solver.variant));
    out["start"] = solved.start;
    std::cout << out.dump() << '\n';
  } else {
    std::cout << s.report(to_string(config.solver.variant)) << '\n';
    if (solved.start != "the usual start")
      std::cout << fmt::format("started the solve from {}: it costs less on the config's model than u_init\n", solved.start);
    std::cout << fmt::format("cost {:.12g} (expected {:.12g}), final state [{}]\n", r.nominal_cost, r.expected_cost,
                             fmt::join(as_list(x_final), ", "));
  }
  if (s.termination == DdpTermination::Stalled)
    std::cerr << fmt::format("warning: not converged: the cost stopped changing but the gradient |g| = {} is "
                             "absurd against the cost {:.6g} (a trajectory too sensitive to its controls; try a "
                             "smaller system.dt)\n",
                             std::isfinite(s.final_gradient_norm) ? fmt::format("{:.2g}", s.final_gradient_norm) : "not finite",
                             r.nominal_cost);
  else if (s.termination == DdpTermination::InitialRolloutDiverged)
    std::cerr << fmt::format("warning: not converged: the initial controls {} (the cost is that of the states "
                             "reached)\n", initial_rollout_failure(r.nominal_cost));
  return converged(s.termination) ? kExitSuccess : kExitInternalFailure;
}

}  // namespace

void add_solve_command(CLI::App& app, CommandAction& action) {
  auto file = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("solve", "Solve one trajectory-optimisation problem described in a TOML file");
  cmd->add_option("CONFIG", *file,
                  "TOML problem description (docs/formats.md#problem-config-gpilqg-solve-and-gpilqg-plan)")
      ->required();
  cmd->add_flag("--json", *json, "Print one JSON document: cost, iterations, termination, x_final, u, solve_time_s, start");
  cmd->callback([&action, file, json] { action = [file, json] { return run_solve(*file, *json); }; });
}

}  // namespace gpilqg::cli
