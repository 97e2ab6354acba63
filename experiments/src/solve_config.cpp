#include "gpilqg/experiments/solve_config.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gpilqg/control/best_start.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/experiments/config_model.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/reference_plans.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {

SolveConfig read_solve_config(const std::filesystem::path& file) {
  const toml::table root = TomlFields::parse(file);
  return read_solve_config(TomlFields(root, file), {}, "ilqr");
}

SolveConfig read_solve_config(const TomlFields& f, const std::vector<std::string>& extra_sections,
                              const std::string& default_algorithm,
                              const std::vector<std::string>& extra_noise_keys) {
  std::vector<std::string> sections = {"system", "noise", "problem", "solver"};
  sections.insert(sections.end(), extra_sections.begin(), extra_sections.end());
  f.only_keys("", sections);
  f.require_section("system");
  f.require_section("problem");
  f.only_keys("system", {"name", "preset", "model", "integrator", "dt", "substeps"});
  std::vector<std::string> noise_keys = {"actuator_additive", "actuator_multiplicative", "state"};
  noise_keys.insert(noise_keys.end(), extra_noise_keys.begin(), extra_noise_keys.end());
  f.only_keys("noise", noise_keys);
  f.only_keys("problem", {"horizon", "x0", "goal", "Q", "R", "Qf", "u_min", "u_max", "u_init"});
  f.only_keys("solver", {"algorithm", "max_iterations", "tolerance", "gradient_tolerance", "regularization",
                         "max_seconds"});

  SolveConfig c;
  c.system = f.system_name("system.name");
  const SystemSignature signature = f.system("system.name");
  if (signature.controls.empty()) f.fail("system.name", passive_system_refusal(c.system));
  const int n = static_cast<int>(signature.states.size());
  const int m = static_cast<int>(signature.controls.size());

  const std::string preset = f.string("system.preset", "sim");
  const auto parsed_preset = parse_preset(preset);
  if (!parsed_preset) f.fail("system.preset", fmt::format("'{}'; expected \"sim\" or \"real\"", preset));
  if (f.has("system.model") && f.has("system.preset"))
    f.fail("system.preset", "is given with system.model, whose file names its own preset; expected one of the two");
  c.simulator = read_config_model(f, "system.model", c.system, *parsed_preset);
  if (!f.own_integrator(c.system, "system.integrator", "system.substeps")) {
    c.integrator = f.integrator("system.integrator", "euler");
    c.substeps = f.integer_in("system.substeps", 1, limits::kMaxSubsteps, 1);
  }
  c.dt = f.number("system.dt");
  if (c.dt <= 0.0) f.fail("system.dt", "must be > 0");

  c.noise.additive_std = f.vector("noise.actuator_additive", m, Vector());
  c.noise.multiplicative_std = f.vector("noise.actuator_multiplicative", m, Vector());
  c.noise.state_std = f.state_vector("noise.state", n, Vector());
  for (const char* field : {"noise.actuator_additive", "noise.actuator_multiplicative", "noise.state"})
    if (f.has(field) && (f.vector(field, -1).array() < 0.0).any()) f.fail(field, "has negative entries; expected standard deviations >= 0");

  c.horizon = f.integer_in("problem.horizon", 1, limits::kMaxHorizon);
  if (const auto problem = limits::trajectory_memory_problem(c.horizon, n, m, false)) f.fail("problem.horizon", *problem);
  c.x0 = f.state_vector("problem.x0", n);
  c.goal = f.state_vector("problem.goal", n);
  c.Q = f.weight_vector("problem.Q", n);
  c.R = f.weight_vector("problem.R", m);
  c.Qf = f.weight_vector("problem.Qf", n);
  c.u_min = f.vector("problem.u_min", m, Vector());
  c.u_max = f.vector("problem.u_max", m, Vector());
  if (c.u_min.size() && c.u_max.size() && (c.u_min.array() > c.u_max.array()).any())
    f.fail("problem.u_min", "exceeds problem.u_max");
  c.u_init = f.control_vector("problem.u_init", m, Vector());

  const std::string algorithm = f.string("solver.algorithm", default_algorithm);
  if (auto v = parse_variant(algorithm)) c.solver.variant = *v;
  else f.fail("solver.algorithm", fmt::format("'{}'; expected \"ilqr\", \"ilqg\" or \"robust_ilqg\"", algorithm));
  c.solver.max_iterations =
      f.integer_in("solver.max_iterations", 1, limits::kMaxSolverIterations, c.solver.max_iterations);
  c.solver.cost_tolerance = f.number("solver.tolerance", c.solver.cost_tolerance);
  c.solver.gradient_tolerance = f.number("solver.gradient_tolerance", c.solver.gradient_tolerance);
  c.solver.max_seconds = f.number("solver.max_seconds", c.solver.max_seconds);
  const std::string regularization = f.string("solver.regularization", "control");
  if (auto r = parse_regularization(regularization)) c.solver.regularization = *r;
  else f.fail("solver.regularization", fmt::format("'{}'; expected \"control\" or \"value\"", regularization));
  try {
    c.solver.validate();
  } catch (const std::invalid_argument& e) {
    f.fail("solver", e.what());
  }
  c.files = config_files(f, {"system.name", "system.model"});
  return c;
}

std::shared_ptr<const StepModel> make_solve_model(const SolveConfig& c) {
  return make_step_model(c.simulator.build(c.noise), c.integrator, c.dt, c.substeps);
}

QuadraticCost make_solve_cost(const SolveConfig& c) {
  return QuadraticCost(c.dt, c.Q.asDiagonal(), c.R.asDiagonal(), c.Qf.asDiagonal(), c.goal);
}

SolvedConfig solve_config(const SolveConfig& c) {
  const auto step_model = make_solve_model(c);
  const QuadraticCost cost = make_solve_cost(c);
  const DdpTask task = ddp_task(c, cost);
  const DdpProblem problem = ddp_problem(task, *step_model);
  const ReferencePlans references =
      reference_plans(task, c.solver.variant, LoopModel{c.simulator, c.integrator, c.substeps, c.dt}, c.noise, c.simulator);
  std::vector<Matrix> starts{task.u_init.replicate(1, c.horizon)};
  for (const AffinePolicy& kept : references.policies) starts.push_back(closed_loop_controls(*step_model, kept, c.x0));
  DdpSolver solver(c.solver);
  BestStart best = solve_from_best_start(solver, problem, starts);
  return {std::move(best.result), references.start_name(best.start)};
}

std::string initial_rollout_failure(double cost) {
  if (std::isfinite(cost))
    return fmt::format("drive the model beyond the divergence bound (a state not finite or beyond |x| = {:g}); "
                       "try another problem.u_init",
                       kDivergedStateMagnitude);
  return fmt::format("keep every state within the divergence bound (|x| <= {:g}), but their cost overflowed (not a "
                     "finite number); try smaller cost weights Q, R, Qf or a shorter system.dt",
                     kDivergedStateMagnitude);
}

}  // namespace gpilqg
