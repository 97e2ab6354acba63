#include "gpilqg/experiments/run_config.hpp"

#include <cctype>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/utf8.hpp"
#include "gpilqg/experiments/config_model.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/toml_fields.hpp"
#include "gpilqg/gp/fitted_moment_matcher.hpp"

namespace gpilqg {
namespace {

/// Why `name` cannot name a task, or "": a task is the root group `/<name>` of the result file
/// (docs/formats.md), so its name must be a valid HDF5 link name of that group: non-empty, UTF-8,
/// without '/', whitespace or control characters, neither "." nor ".." (HDF5 reads "." as the
/// group itself) nor a name the root already holds (the dataset `/seeds`).
std::string task_name_problem(const std::string& name) {
  constexpr const char* kRule =
      "expected a non-empty name without '/', whitespace or control characters, not '.', '..' or 'seeds' (it "
      "names the task's HDF5 group /<name> in the result file)";
  if (name.empty()) return fmt::format("is empty; {}", kRule);
  if (name == "." || name == ".." || name == "seeds")
    return fmt::format("'{}' is reserved by the result file's layout; {}", name, kRule);
  for (const char c : name)
    if (c == '/' || std::isspace(static_cast<unsigned char>(c)) || std::iscntrl(static_cast<unsigned char>(c)))
      return fmt::format("'{}' holds {}; {}", escaped_bytes(name), c == '/' ? "'/'" : "whitespace or a control character", kRule);
  if (!is_valid_utf8(name)) return fmt::format("'{}' is not valid UTF-8; {}", escaped_bytes(name), kRule);
  return {};
}

/// Reads the [[tasks]] array: at least one task, every field present (a replaced array has no
/// defaults to fall back on), names unique.
std::vector<RunTask> read_tasks(const TomlFields& f, const toml::table& root, int n, int m) {
  const toml::array* tasks = root["tasks"].as_array();
  if (tasks == nullptr || tasks->empty()) f.fail("tasks", "expected a non-empty array of [[tasks]] tables");
  std::vector<RunTask> out;
  for (std::size_t i = 0; i < tasks->size(); ++i) {
    const std::string p = fmt::format("tasks[{}]", i);
    if (!(*tasks)[i].is_table()) f.fail(p, "is not a table; expected [[tasks]]");
    f.only_keys(p, {"name", "x0", "goal", "horizon", "Q", "R", "Qf", "track_line", "transfer"});
    RunTask t;
    t.name = f.string(p + ".name");
    if (const std::string problem = task_name_problem(t.name); !problem.empty()) f.fail(p + ".name", problem);
    for (const auto& earlier : out)
      if (earlier.name == t.name) f.fail(p + ".name", fmt::format("'{}' is used by two tasks", t.name));
    t.x0 = f.state_vector(p + ".x0", n);
    t.goal = f.state_vector(p + ".goal", n);
    t.horizon = f.integer_in(p + ".horizon", 2, limits::kMaxHorizon);
    t.Q = f.weight_vector(p + ".Q", n);
    t.R = f.weight_vector(p + ".R", m);
    t.Qf = f.weight_vector(p + ".Qf", n);
    if ((t.R.array() <= 0.0).any()) f.fail(p + ".R", "must be > 0 (the control weight makes each step well posed)");
    const auto flag = [&](const std::string& key) {
      const toml::node* node = root.at_path(p + "." + key).node();
      if (node == nullptr) f.fail(p + "." + key, "missing; expected true or false");
      if (!node->is_boolean()) f.fail(p + "." + key, "is not a boolean; expected true or false");
      return node->as_boolean()->get();
    };
    t.track_line = flag("track_line");
    t.transfer = flag("transfer");
    if (i == 0 && t.transfer) f.fail(p + ".transfer", "the first task has no previous task to transfer from");
    out.push_back(std::move(t));
  }
  return out;
}

/// The same registered name, or two paths of the same model file.
bool same_system(const std::string& a, const std::string& b) {
  if (a == b) return true;
  if (!is_model_file_name(a) || !is_model_file_name(b)) return false;
  std::error_code ea, eb;
  const auto ca = std::filesystem::weakly_canonical(a, ea), cb = std::filesystem::weakly_canonical(b, eb);
  return !ea && !eb && ca == cb;
}

Vector non_negative(const TomlFields& f, const std::string& path, int size, std::optional<Vector> fallback = std::nullopt) {
  Vector v = f.vector(path, size, std::move(fallback));
  if ((v.array() < 0.0).any()) f.fail(path, "has negative entries; expected standard deviations >= 0");
  return v;
}

/// [world]: `model`, another model file with the same states and controls or a model file of the
/// diagnosis (config_model.hpp), relative to the config's folder, and `parameters`, overrides by
/// parameter name; both optional. Every override is checked by building the world once.
void read_world(const TomlFields& f, const toml::table& root, RunConfig& c, const SystemSignature& signature) {
  c.world.system = c.system;
  c.world.preset = Preset::RealWorld;
  if (!f.has("world")) return;
  f.only_keys("world", {"model", "parameters"});
  if (f.has("world.model") && is_diagnosis_model_file(f.string("world.model"))) {
    c.world = read_config_model(f, "world.model", c.system, Preset::RealWorld);
  } else if (f.has("world.model")) {
    c.world.system = f.system_name("world.model");
    const std::string mismatch = signature_mismatch(signature, system_signature(c.world.system));
    if (!mismatch.empty()) f.fail("world.model", mismatch);
  }
  if (const toml::node* node = root.at_path("world.parameters").node()) {
    const toml::table* table = node->as_table();
    if (table == nullptr) f.fail("world.parameters", "is not a table; expected name = value entries");
    for (const auto& [key, value] : *table) {
      const std::string field = "world.parameters." + toml_key(std::string(key.str()));
      try {
        c.world = with_parameter(c.world, std::string(key.str()), f.number(field));
      } catch (const std::invalid_argument& e) {
        f.fail(field, e.what());
      }
    }
  }
  try {
    (void)c.world.build(ActuatorNoise{});
  } catch (const std::invalid_argument& e) {
    f.fail("world.parameters", e.what());
  }
}

/// The config's text as the result file keeps it: with every file it names (system.model, world.model)
/// as resolved against the config's folder, so that the text means the same read from anywhere.
std::string stored_text(const TomlFields& f, const toml::table& root) {
  toml::table stored = root;
  for (const char* table : {"system", "world"})
    if (const std::string path = fmt::format("{}.model", table); f.has(path))
      if (toml::table* section = stored[table].as_table()) section->insert_or_assign("model", f.file_path(path).string());
  std::ostringstream text;
  text << toml::toml_formatter{stored};
  return text.str();
}

RunConfig read_run_config(const toml::table& root, const std::string& source, const std::string& system) {
  const TomlFields f(root, source);
  f.only_keys("", {"system", "world", "noise", "control", "tasks", "loop", "diagnosis", "gp", "solver", "mpc", "pddp"});
  f.only_keys("system", {"name", "model", "dt", "integrator", "substeps"});
  RunConfig c;
  c.system = f.system_name("system.name");
  if (!same_system(c.system, system))
    f.fail("system.name", fmt::format("is '{}' but the command runs '{}'", c.system, system));
  const SystemSignature signature = f.system("system.name");
  if (signature.controls.empty()) f.fail("system.name", passive_system_refusal(c.system));
  const int n = static_cast<int>(signature.states.size());
  const int m = static_cast<int>(signature.controls.size());

  c.dt = f.number("system.dt");
  if (c.dt <= 0.0) f.fail("system.dt", "must be > 0");
  if (!f.own_integrator(c.system, "system.integrator", "system.substeps")) {
    c.integrator = f.integrator("system.integrator");
    c.substeps = f.integer_in("system.substeps", 1, limits::kMaxSubsteps);
  }

  c.simulator = read_config_model(f, "system.model", c.system, Preset::Simulator);
  read_world(f, root, c, signature);

  c.noise.multiplicative_std = non_negative(f, "noise.actuator_multiplicative", m, Vector());
  c.noise.additive_std = non_negative(f, "noise.actuator_additive", m, Vector());
  c.observation_std = non_negative(f, "noise.observation", n, Vector::Zero(n));
  (void)f.state_vector("noise.observation", n, Vector::Zero(n));  // a std in state units: bounded like a state

  c.u_init = f.control_vector("control.u_init", m);
  c.u_min = f.vector("control.u_min", m, Vector());
  c.u_max = f.vector("control.u_max", m, Vector());
  if (c.u_min.size() && c.u_max.size() && (c.u_min.array() > c.u_max.array()).any())
    f.fail("control.u_min", "exceeds control.u_max");

  c.tasks = read_tasks(f, root, n, m);

  c.iterations = f.integer_in("loop.iterations", 1, limits::kMaxLoopIterations);
  c.rollouts = f.integer_in("loop.rollouts", 1, limits::kMaxRollouts);
  c.exploration_std = non_negative(f, "loop.exploration", m);
  c.policy_tolerance = f.number("loop.policy_tolerance");
  if (c.policy_tolerance < 0.0) f.fail("loop.policy_tolerance", "must be >= 0");
  c.evaluation_rollouts = f.integer_in("loop.evaluation_rollouts", 1, limits::kMaxRollouts);

  f.only_keys("diagnosis", {"after_round"});
  c.diagnose_after = f.integer_in("diagnosis.after_round", -1, limits::kMaxLoopIterations, -1);
  if (c.diagnose_after >= c.iterations)
    f.fail("diagnosis.after_round", fmt::format("is {}; expected -1 (no diagnosis) or a round from 0 to {} (loop.iterations "
                                                "- 1: the last round whose rollouts a later plan uses)",
                                                c.diagnose_after, c.iterations - 1));

  c.gp = read_gp_settings(f, GpSettings{});  // every field is in the merged defaults

  c.solver.max_iterations = f.integer_in("solver.max_iterations", 1, limits::kMaxSolverIterations);
  c.solver.cost_tolerance = f.number("solver.tolerance");
  c.solver.gradient_tolerance = f.number("solver.gradient_tolerance");
  // Iterations are a run's only limit on a solve: DdpOptions' default 60 s wall-time cap stopped the
  // quadrotor's full-horizon Robust-iLQG solves on 600 GP points part-way (WallTime) when the machine
  // was loaded, so results depended on the load. The largest double never binds (a finite value is required).
  c.solver.max_seconds = std::numeric_limits<double>::max();
  const std::string gp_algorithm = f.string("solver.gp_algorithm");
  if (gp_algorithm == "robust_ilqg") c.gp_variant = DdpVariant::RobustILQG;
  else if (gp_algorithm == "ilqg") c.gp_variant = DdpVariant::ILQG;
  else f.fail("solver.gp_algorithm", fmt::format("'{}'; expected \"robust_ilqg\" (the paper) or \"ilqg\" (GP mean only)", gp_algorithm));
  try {
    c.solver.validate();
  } catch (const std::invalid_argument& e) {
    f.fail("solver", e.what());
  }

  c.mpc = f.boolean("mpc.enabled");
  if (c.mpc) {
    c.mpc_options.horizon = f.integer_in("mpc.horizon", 1, limits::kMaxHorizon);
    c.mpc_options.first_solve_iterations = f.integer_in("mpc.first_solve_iterations", 1, limits::kMaxSolverIterations);
    c.mpc_options.iterations_per_step = f.integer_in("mpc.iterations_per_step", 1, limits::kMaxSolverIterations);
  }

  c.pddp = f.boolean("pddp.enabled");
  c.pddp_max_iterations = f.integer_in("pddp.max_iterations", 1, limits::kMaxSolverIterations);
  c.pddp_backend = f.string("pddp.backend");
  try {
    gp::require_moment_matching(c.pddp_backend, "");
  } catch (const std::invalid_argument& e) {
    f.fail("pddp.backend", e.what());
  }
  c.pddp_own = f.boolean("pddp.own");
  c.pddp_own_initial_rollouts = f.integer_in("pddp.own_initial_rollouts", 1, limits::kMaxRollouts);
  c.pddp_own_amplitude = non_negative(f, "pddp.own_amplitude", m);

  for (std::size_t i = 0; i < c.tasks.size(); ++i)
    if (const auto problem = limits::trajectory_memory_problem(c.tasks[i].horizon, n, m, c.pddp))
      f.fail(fmt::format("tasks[{}].horizon", i), *problem);

  c.text = stored_text(f, root);
  c.files = config_files(f, {"system.name", "system.model", "world.model"});
  c.files_text = config_files_text(c.files);
  return c;
}

}  // namespace

const std::string& default_run_config_text(const std::string& system) {
  try {
    return find_system(system)->default_run_config;  // entries live as long as the registry
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("run: {}", e.what()));
  }
}

RunConfig parse_run_config(const std::string& system, const std::string& override_text, const std::string& source) {
  const std::string& default_text = default_run_config_text(system);
  if (default_text.empty()) {
    // A system without a default config (a MuJoCo model, most plugins): the file is the whole config.
    if (override_text.empty())
      throw InputError(fmt::format("run: system '{}' has no default config; give a complete one with --config "
                                   "(docs/own-system.md shows one)", system));
    return read_run_config(TomlFields::parse_text(override_text, source), source, system);
  }
  const std::string defaults_source = fmt::format("<embedded defaults of run {}>", system);
  const toml::table defaults = TomlFields::parse_text(default_text, defaults_source);
  if (override_text.empty()) return read_run_config(defaults, defaults_source, system);
  toml::table root = TomlFields::parse_text(override_text, source);
  // Optional fields without a default: the simulator's and the world's model files, world overrides.
  TomlFields::merge(root, defaults, {"system.model", "world", "world.model", "world.parameters", "diagnosis"});
  return read_run_config(root, source, system);
}

RunConfig load_run_config(const std::string& system, const std::optional<std::filesystem::path>& override_file) {
  if (!override_file) return parse_run_config(system, "", "");
  check_input_file_as<InputError>(*override_file, kMaxConfigFileBytes, "a TOML config");
  std::ifstream in(*override_file);
  std::stringstream text;
  text << in.rdbuf();
  return parse_run_config(system, text.str(), override_file->string());
}

RunConfig with_iterations(RunConfig config, int iterations, const std::string& option) {
  if (iterations < 1 || iterations > limits::kMaxLoopIterations)
    throw InputError(fmt::format("{}: is {}; expected a whole number from 1 to {}", option, iterations,
                                 limits::kMaxLoopIterations));
  if (config.diagnose_after >= iterations)
    throw InputError(fmt::format("{} {}: the config's diagnosis.after_round is {}, a round the loop of {} iteration(s) "
                                 "never reaches (its rounds are 0 to {}); expected more iterations, or an earlier "
                                 "after_round (-1: no diagnosis)",
                                 option, iterations, config.diagnose_after, iterations, iterations - 1));
  config.iterations = iterations;
  toml::table stored = toml::parse(config.text);
  if (toml::table* loop = stored["loop"].as_table()) loop->insert_or_assign("iterations", iterations);
  std::ostringstream text;
  text << toml::toml_formatter{stored};
  config.text = text.str();
  return config;
}

}  // namespace gpilqg
