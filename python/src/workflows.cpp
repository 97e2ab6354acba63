/// The library's workflows from Python, each the same code as its command: diagnose (`gpilqg
/// diagnose --json`), solve (`gpilqg solve`), plan (`gpilqg plan`, with the Policy it returns), run
/// (`gpilqg run`). Each runs without the GIL, reports progress to an optional Python callback, and
/// stops on Ctrl-C within one iteration (LongCall).

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include <fmt/format.h>

#include "bindings.hpp"
#include "conversions.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/output_path.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/diagnose_request.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"
#include "gpilqg/experiments/planning.hpp"
#include "gpilqg/experiments/run_config.hpp"
#include "gpilqg/experiments/run_experiment.hpp"
#include "gpilqg/experiments/run_results_io.hpp"
#include "gpilqg/experiments/solve_config.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg::python {
namespace {

/// A policy of `gpilqg plan` (docs/formats.md, "Policy file") with the GP it was planned on and, with
/// `diagnose`, the diagnosis of its data.
struct Policy {
  PolicyFile file;
  std::shared_ptr<const gp::ResidualModel> model;
  std::optional<LoopDiagnosis> diagnosis;
};

/// Progress lines of a DDP solve, and Ctrl-C between its iterations.
void watch_iterations(DdpOptions& options, LongCall& call) {
  options.on_iteration = [&call](const DdpIteration& r) {
    return call.checkpoint(fmt::format("iteration {}: cost {:.6g}{}", r.iteration, r.cost, r.accepted ? "" : " (rejected)"));
  };
}

/// (T+1, n) from the library's n x (T+1): one row per time step, as in the files.
Matrix rows(const Matrix& columns) { return columns.transpose(); }

/// K as a (T, m, n) array.
py::array_t<double> gains(const std::vector<Matrix>& K, Eigen::Index m, Eigen::Index n) {
  py::array_t<double> out({static_cast<py::ssize_t>(K.size()), static_cast<py::ssize_t>(m), static_cast<py::ssize_t>(n)});
  auto view = out.mutable_unchecked<3>();
  for (std::size_t t = 0; t < K.size(); ++t)
    for (Eigen::Index j = 0; j < m; ++j)
      for (Eigen::Index i = 0; i < n; ++i) view(static_cast<py::ssize_t>(t), j, i) = K[t](j, i);
  return out;
}

py::dict summary_dict(const DdpSummary& s) {
  py::dict d;
  d["termination"] = std::string(to_string(s.termination));
  d["converged"] = converged(s.termination);
  d["iterations"] = s.iterations;
  d["initial_cost"] = s.initial_cost;
  d["final_cost"] = s.final_cost;
  d["gradient_norm"] = s.final_gradient_norm;
  d["solve_time_s"] = s.timings.total_s;
  return d;
}

/// A config given as a file path, or as TOML text (the package turns dicts into TOML text).
struct ConfigSource {
  std::optional<std::filesystem::path> file;
  std::string text;
};

/// Refuses, before any work, an output `file` of `call` (given as argument `argument`) that cannot
/// be written, would replace one of `inputs` or does not carry `format`'s extension (output_problem),
/// as the command line refuses its --out.
void check_output(const std::string& call, const std::string& argument, const std::optional<std::filesystem::path>& file,
                  const OutputFormat& format, const std::vector<NamedInput>& inputs) {
  if (!file) return;
  if (const auto problem = output_problem(*file, format, inputs))
    throw InputError(fmt::format("{}: {} {}: {}", call, argument, file->string(), *problem));
}

/// The files a call reads: the config (when a file) and the files it names.
std::vector<NamedInput> config_inputs(const ConfigSource& source, const std::vector<NamedInput>& named) {
  std::vector<NamedInput> out = named;
  if (source.file) out.push_back({"config", *source.file});
  return out;
}

SolveConfig solve_config_of(const ConfigSource& source) {
  if (source.file) return read_solve_config(*source.file);
  const toml::table root = TomlFields::parse_text(source.text, "<config>");
  return read_solve_config(TomlFields(root, "<config>"), {}, "ilqr");
}

PlanConfig plan_config_of(const ConfigSource& source) {
  if (source.file) return read_plan_config(*source.file);
  const toml::table root = TomlFields::parse_text(source.text, "<config>");
  return read_plan_config(TomlFields(root, "<config>"));
}

py::dict solve(const ConfigSource& source, const py::object& progress) {
  SolveConfig config = solve_config_of(source);
  LongCall call(progress);
  watch_iterations(config.solver, call);
  const SolvedConfig solved = call.run<SolvedConfig>([&] { return solve_config(config); });
  const DdpResult& r = solved.result;
  py::dict out = summary_dict(r.summary);
  out["cost"] = r.nominal_cost;
  out["expected_cost"] = r.expected_cost;
  out["algorithm"] = std::string(to_string(config.solver.variant));
  out["start"] = solved.start;
  out["x"] = rows(r.trajectory.x);
  out["u"] = rows(r.trajectory.u);
  Policy policy;
  policy.file.policy = file_policy(r.policy);
  policy.file.dt = config.dt;
  policy.file.system = config.system;
  const SystemSignature signature = system_signature(config.system);
  policy.file.state_names = names_of(signature.states);
  policy.file.control_names = names_of(signature.controls);
  policy.file.predicted_cost = r.nominal_cost;
  policy.file.expected_cost = r.expected_cost;
  out["policy"] = py::cast(std::move(policy));
  return out;
}

Policy plan(const ConfigSource& source, const std::vector<std::filesystem::path>& data,
            const std::optional<std::filesystem::path>& previous, const std::optional<std::filesystem::path>& out,
            std::uint64_t seed, bool diagnose, const std::optional<std::filesystem::path>& write_model,
            const py::object& progress) {
  if (write_model && !diagnose) throw InputError("plan: write_model needs diagnose=True");
  PlanRequest request;
  request.diagnose = diagnose;
  request.config = plan_config_of(source);
  std::vector<NamedInput> inputs = config_inputs(source, request.config.problem.files);
  for (const auto& file : data) inputs.push_back({"data", file});
  if (previous) inputs.push_back({"previous", *previous});
  check_output("plan", "out", out, {"plan writes an HDF5 policy file", kHdf5Extensions}, inputs);
  check_output("plan", "write_model", write_model, {"plan writes a TOML model file", kTomlExtensions}, inputs);
  if (out && write_model && same_file(*write_model, *out))
    throw InputError("plan: write_model and out name the same file; expected two files");
  request.data_files = data;
  request.previous = previous;
  request.seed = seed;
  LongCall call(progress);
  watch_iterations(request.config.problem.solver, call);
  PlannedPolicy planned = call.run<PlannedPolicy>([&] { return plan_policy(request); });
  if (planned.summary.termination == DdpTermination::InitialRolloutDiverged)
    throw std::runtime_error("the initial controls drive the model to non-finite states; no policy");
  if (out) write_policy_file(*out, planned.file, planned.model.get());
  if (write_model && planned.diagnosis)
    diagnosis::write_model_file(*write_model, planned.planned_on,
                                {planned.diagnosis->adopted
                                     ? "diagnosed by gpilqg.plan(diagnose=True)"
                                     : "the config's simulator, kept by gpilqg.plan(diagnose=True) (verdict " +
                                           planned.diagnosis->verdict + ")"});
  return {std::move(planned.file), std::move(planned.model), std::move(planned.diagnosis)};
}

std::string run(const std::string& system, const ConfigSource& source, int seeds, std::uint64_t first_seed,
                std::optional<int> iterations, const std::vector<std::string>& backends, const std::filesystem::path& out,
                const py::object& progress) {
  if (system_signature(system).controls.empty()) throw InputError(passive_system_refusal(system));
  RunConfig config = source.file ? load_run_config(system, *source.file)
                                 : (source.text.empty() ? load_run_config(system, std::nullopt)
                                                        : parse_run_config(system, source.text, "<config>"));
  if (iterations) config = with_iterations(std::move(config), *iterations, "run: iterations");
  if (seeds < 1) throw InputError(fmt::format("seeds {}: expected >= 1", seeds));
  check_output("run", "out", out, {"run writes an HDF5 result file", kHdf5Extensions}, config_inputs(source, config.files));
  RunOptions options;
  options.seeds.clear();
  for (int s = 0; s < seeds; ++s) options.seeds.push_back(first_seed + static_cast<std::uint64_t>(s));
  options.backends = backends;
  LongCall call(progress);
  options.progress = [&call](const std::string& line) { call.throwing_checkpoint(line); };
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  call.run<int>([&] {
    write_run_results(out, run_experiment(config, options));
    return 0;
  });
  return out.string();
}

py::object diagnose(const py::object& system, const py::object& data, const std::string& model,
                    const std::string& preset, const std::vector<std::string>& add, bool auto_select,
                    const std::optional<std::string>& search, const std::vector<int>& horizons, const std::string& integrator,
                    double heldout, int gp_points, int gp_restarts, const std::string& backend, std::uint64_t seed,
                    const std::string& criterion, std::optional<long> window, const std::vector<std::string>& exclude,
                    const std::vector<std::string>& include, const py::object& progress) {
  diagnosis::DiagnoseRequest request;
  request.system = py::isinstance<py::str>(system) ? system.cast<std::string>() : system_from_python(system, "diagnose")->name();
  request.model_file = model;
  request.preset = preset;
  request.add = add;
  request.auto_select = auto_select;
  request.search = search;
  request.horizons = horizons;
  request.integrator = integrator;
  request.heldout = heldout;
  request.gp_points = gp_points;
  request.gp_restarts = gp_restarts;
  request.backend = backend;
  request.seed = seed;
  request.criterion = criterion;
  request.window = window;
  request.exclude = exclude;
  request.include = include;
  diagnosis::DiagnosisOptions options = diagnosis::diagnosis_options(request);
  LongCall call(progress);
  options.progress = [&call](const std::string& line) { call.throwing_checkpoint(line); };
  const bool in_memory = py::isinstance<MeasurementSet>(data);
  const std::filesystem::path file =
      in_memory ? std::filesystem::path()
                : path_argument(data, "diagnose", "data", "a gpilqg.MeasurementSet or a measurement file path");
  const MeasurementSet set = in_memory ? data.cast<MeasurementSet>() : read_measurements(file, system_signature(request.system));
  const std::string source = in_memory ? std::string("the MeasurementSet given as data") : file.string();
  const nlohmann::json report = call.run<nlohmann::json>([&] {
    return diagnosis::blame_for_diagnosis(source, [&] { return diagnosis::report_json(diagnosis::diagnose(set, options)); });
  });
  return to_python(report);
}

ConfigSource source_of(const py::object& config) {
  ConfigSource s;
  if (config.is_none()) return s;
  if (py::isinstance<py::str>(config) && config.cast<std::string>().find('\n') != std::string::npos) {
    s.text = config.cast<std::string>();  // TOML text (what the package makes of a dict)
    return s;
  }
  s.file = path_argument(config, "config", "config", "a config file path or TOML text");
  return s;
}

}  // namespace

void bind_workflows(py::module_& m) {
  py::class_<Policy>(m, "Policy", R"(
An affine feedback policy (docs/formats.md, "Policy file"): u_t = clip(u_bar[t] + K[t] (x - x_bar[t]), u_min, u_max).
Call it as policy(t, x). Arrays have one row per time step: x_bar (T+1, n), u_bar (T, m), K (T, m, n).)")
      .def("__call__", [](const Policy& p, int t, const py::object& x_in) {
             if (t < 0 || t >= p.file.policy.horizon())
               throw py::index_error(fmt::format("t = {}: the policy has steps 0 to {}", t, p.file.policy.horizon() - 1));
             const Quantities states{p.file.policy.x_bar.rows(),
                                     fmt::format("the states of the policy's system '{}'", p.file.system)};
             const Vector x = vector_argument(x_in, states, "Policy", "x");
             Vector u(p.file.policy.u_bar.rows());
             p.file.policy.control(t, x, u);
             require_finite_result(u, "Policy", "u", fmt::format("step {} and this finite x (the policy's gains are not finite there)", t));
             return u;
           }, py::arg("t"), py::arg("x"),
           "The control (m,) at step t for the measured state x (n,); gpilqg.InputError for a wrong shape or a "
           "non-finite x.")
      .def_property_readonly("x_bar", [](const Policy& p) { return rows(p.file.policy.x_bar); })
      .def_property_readonly("u_bar", [](const Policy& p) { return rows(p.file.policy.u_bar); })
      .def_property_readonly("K", [](const Policy& p) {
        return gains(p.file.policy.K, p.file.policy.u_bar.rows(), p.file.policy.x_bar.rows());
      })
      .def_property_readonly("u_min", [](const Policy& p) -> py::object {
        return p.file.policy.u_min.size() ? py::cast(p.file.policy.u_min) : py::none();
      })
      .def_property_readonly("u_max", [](const Policy& p) -> py::object {
        return p.file.policy.u_max.size() ? py::cast(p.file.policy.u_max) : py::none();
      })
      .def_property_readonly("horizon", [](const Policy& p) { return p.file.policy.horizon(); })
      .def_property_readonly("dt", [](const Policy& p) { return p.file.dt; })
      .def_property_readonly("system", [](const Policy& p) { return p.file.system; })
      .def_property_readonly("simulator_model", [](const Policy& p) { return p.file.simulator_model; },
                             "str: the simulator planned on, as the text of a model file of `gpilqg diagnose`")
      .def_property_readonly("diagnosis", [](const Policy& p) -> py::object {
            if (!p.diagnosis) return py::none();
            const LoopDiagnosis& d = *p.diagnosis;
            py::dict out;
            out["verdict"] = d.verdict;
            out["reason"] = d.reason;
            out["adopted"] = d.adopted;
            out["changes"] = d.changes;
            out["transitions"] = d.transitions;
            out["model"] = d.adopted ? diagnosis::model_file_text(d.model) : std::string();
            return out;
          }, "dict or None: plan(diagnose=True)'s verdict, reason, adopted, changes, transitions, model (file text)")
      .def_property_readonly("state_names", [](const Policy& p) { return p.file.state_names; })
      .def_property_readonly("control_names", [](const Policy& p) { return p.file.control_names; })
      .def_property_readonly("round", [](const Policy& p) { return p.file.round; })
      .def_property_readonly("predicted_cost", [](const Policy& p) { return p.file.predicted_cost; })
      .def_property_readonly("expected_cost", [](const Policy& p) { return p.file.expected_cost; })
      .def_property_readonly("data_files", [](const Policy& p) { return p.file.data_files; })
      .def_property_readonly("has_model", [](const Policy& p) { return p.model != nullptr; },
                             "whether the policy was planned on a fitted residual GP")
      .def("write", [](const Policy& p, const std::filesystem::path& file) {
             write_policy_file(file, p.file, p.model.get());
           }, py::arg("file"), "Writes the policy file (HDF5, atomically), with /model when there is one.");

  m.def("read_policy", [](const std::filesystem::path& file) { return Policy{read_policy_file(file), nullptr, std::nullopt}; },
        py::arg("file"), "Reads a policy file of `gpilqg plan` (its /model is not loaded).");

  m.def("_solve", [](const py::object& config, const py::object& progress) { return solve(source_of(config), progress); },
        py::arg("config"), py::arg("progress") = py::none());
  m.def("_plan",
        [](const py::object& config, const std::vector<std::filesystem::path>& data,
           const std::optional<std::filesystem::path>& previous, const std::optional<std::filesystem::path>& out,
           std::uint64_t seed, bool diagnose, const std::optional<std::filesystem::path>& write_model,
           const py::object& progress) {
          return plan(source_of(config), data, previous, out, seed, diagnose, write_model, progress);
        },
        py::arg("config"), py::arg("data"), py::arg("previous"), py::arg("out"), py::arg("seed"), py::arg("diagnose"),
        py::arg("write_model"), py::arg("progress"));
  m.def("_run",
        [](const std::string& system, const py::object& config, int seeds, std::uint64_t first_seed,
           std::optional<int> iterations, const std::vector<std::string>& backends, const std::filesystem::path& out,
           const py::object& progress) {
          return run(system, source_of(config), seeds, first_seed, iterations, backends, out, progress);
        },
        py::arg("system"), py::arg("config"), py::arg("seeds"), py::arg("first_seed"), py::arg("iterations"),
        py::arg("backends"), py::arg("out"), py::arg("progress"));
  const diagnosis::DiagnoseRequest defaults;
  m.def("diagnose", &diagnose, py::arg("system"), py::arg("data"), py::arg("model") = "",
        py::arg("preset") = defaults.preset, py::arg("add") = std::vector<std::string>{},
        py::arg("auto") = false, py::arg("search") = py::none(), py::arg("horizons") = defaults.horizons, py::arg("integrator") = defaults.integrator, py::arg("heldout") = defaults.heldout,
        py::arg("gp_points") = defaults.gp_points, py::arg("gp_restarts") = defaults.gp_restarts,
        py::arg("backend") = defaults.backend, py::arg("seed") = defaults.seed,
        py::arg("criterion") = defaults.criterion, py::arg("window") = py::none(), py::arg("exclude") = std::vector<std::string>{},
        py::arg("include") = std::vector<std::string>{}, py::arg("progress") = py::none(), R"(
Compares the model with the measurements and names the missing physical effect: the same dict as
`gpilqg diagnose --json` (docs/formats.md), with the same options (model: a model file; add:
["EFFECT", "EFFECT=VALUE", ...]; auto: --auto, several effects, the path under "selection"; search:
--search, "subsets" or "forward"; horizons: --horizons, the k of the k-step predictions; criterion and
window: --criterion and --window, "simulation" with window=N fits and scores the effects on the
simulation error over windows of N samples started from measured states; exclude: --exclude, names or
patterns of candidates never ranked or proposed, e.g. ["param:*.armature"]; include: --include, names or
patterns of candidates searched only on request, e.g. ["param:*.second_moment_*"]). system: a registry name or gpilqg.Dynamics registered by name;
data: a MeasurementSet or a file. progress(line): one line after the residual GP and after every fitted
effect; Ctrl-C stops the call at the next of these points.)");
}

}  // namespace gpilqg::python
