/// `gpilqg diagnose --system NAME --data FILE [--model F.toml] [--add EFFECT[=VALUE]]... [--json]
/// [--out F.h5] [--plots DIR] [--horizons LIST] [--criterion one-step|simulation --window N|inverse-dynamics[-iv]]`: compare
/// a model with measurements, see where it fails, learn which physical effect is missing, add it and
/// watch the error fall (docs/command-line.md#gpilqg-diagnose---system-name---data-file-options; the
/// effects: docs/diagnosis.md#the-physical-effects-library-coreeffect_libraryhpp-coreeffectshpp; the
/// JSON: docs/formats.md#diagnosis-json-gpilqg-diagnose---json).

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "json_arguments.hpp"
#include "gpilqg/core/limits.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/diagnose_request.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"
#include "gpilqg/experiments/diagnosis/report_hdf5.hpp"
#include "gpilqg/experiments/plot_script.hpp"
#include "gpilqg/gp/backend_registry.hpp"

namespace gpilqg::cli {

namespace {

/// The plotting script under experiments/plots/ (plot_script.hpp).
constexpr const char* kPlotScript = "diagnose_plots.py";

struct DiagnoseOptions {
  diagnosis::DiagnoseRequest request;  ///< system, model, preset, add, integrator, heldout, GP settings, seed
  std::string data;
  bool json = false;
  std::string out;
  std::string plots;
  std::string write_model;
  long window = 0;  ///< --window as given (request.window when the option is present)
};

/// Checks, before any work, that plots can be drawn (exit 2 with the missing packages otherwise).
void check_plotting() {
  try {
    require_plotting(kPlotScript);
  } catch (const std::runtime_error& e) {
    throw InputError(std::string("--plots: ") + e.what());
  }
}

/// " --plugin LIB.so" when `system` was registered by a plugin (the entry's origin is the path the
/// plugin was loaded from), so that the commands suggested below run as printed; empty otherwise.
std::string plugin_option(const std::string& system) {
  if (is_model_file_name(system)) return "";
  const std::string& origin = find_system(system)->origin;
  return origin == "built-in" ? "" : " --plugin " + origin;
}

/// " --criterion C [--window N]", " --exclude P" and " --include P" when the request has them, so that
/// the next call uses the same criterion and candidates.
std::string criterion_options(const diagnosis::DiagnoseRequest& r) {
  std::string out = r.window ? fmt::format(" --criterion {} --window {}", r.criterion, *r.window)
                  : r.criterion != diagnosis::DiagnoseRequest{}.criterion ? " --criterion " + r.criterion : "";
  for (const std::string& pattern : r.exclude) out += " --exclude '" + pattern + "'";
  for (const std::string& pattern : r.include) out += " --include '" + pattern + "'";
  return out;
}

int run_diagnose(const DiagnoseOptions& options_given) {
  const DiagnoseOptions& o = options_given;
  const diagnosis::DiagnoseRequest& r = o.request;
  const std::vector<CommandInput> inputs = {{"--data", o.data}, {"--model", r.model_file}, system_input(r.system)};
  check_output_file_option("--out", o.out, {"diagnose writes an HDF5 report", kHdf5Extensions}, inputs);
  check_output_folder_option("--plots", o.plots);
  check_output_file_option("--write-model", o.write_model, {"diagnose writes a TOML model file", kTomlExtensions},
                           inputs);
  const SystemSignature signature = system_signature(r.system);
  diagnosis::DiagnosisOptions options = diagnosis::diagnosis_options(r);
  // Progress on stderr, with --json too (stdout then holds the document alone): a long search on a
  // robot's log is not silent.
  options.progress = [](const std::string& line) { std::cerr << "diagnose: " << line << std::endl; };
  if (!o.plots.empty()) check_plotting();
  const MeasurementSet data = read_measurements(o.data, signature);
  const diagnosis::DiagnosisReport report =
      diagnosis::blame_for_diagnosis(o.data, [&] { return diagnosis::diagnose(data, options); });

  std::filesystem::path h5 = o.out;
  if (h5.empty() && !o.plots.empty()) h5 = std::filesystem::path(o.plots) / "diagnosis.h5";
  if (!o.plots.empty()) std::filesystem::create_directories(o.plots);
  if (!h5.empty()) diagnosis::write_report_hdf5(h5, report);
  if (!o.write_model.empty())
    diagnosis::write_model_file(o.write_model, report.model_next,
                                {fmt::format("written by gpilqg diagnose from {} (verdict: {})", o.data, report.verdict.status),
                                 fmt::format("next: gpilqg diagnose{} --system {} --data {} --model {}{}", plugin_option(r.system),
                                             r.system, o.data, o.write_model, criterion_options(r))});
  if (!o.plots.empty()) {
    // The script's own line goes to stdout; with --json, stdout holds the JSON document only.
    std::cout.flush();
    const int saved = o.json ? ::dup(STDOUT_FILENO) : -1;
    if (saved >= 0 && !std::freopen("/dev/null", "w", stdout)) throw std::runtime_error("cannot silence stdout");
    try {
      run_plot_script(kPlotScript, h5, o.plots);
    } catch (...) {
      if (saved >= 0) ::dup2(saved, STDOUT_FILENO);
      throw;
    }
    if (saved >= 0) {
      std::fflush(stdout);
      ::dup2(saved, STDOUT_FILENO);
      ::close(saved);
    }
  }

  if (o.json) {
    std::cout << diagnosis::report_json(report).dump(2) << '\n';
    return kExitSuccess;
  }
  std::cout << diagnosis::report_text(report);
  if (!h5.empty()) std::cout << "report: " << h5.string() << '\n';
  if (!o.plots.empty()) std::cout << "plots: " << o.plots << '\n';
  if (!o.write_model.empty()) std::cout << "model for the next round: " << o.write_model << '\n';
  if (report.verdict.effect && r.add.empty() && !r.auto_select)
    std::cout << fmt::format("next: gpilqg diagnose{} --system {} --data {}{}{} --add {}\n", plugin_option(r.system),
                             r.system, o.data, r.model_file.empty() ? "" : " --model " + r.model_file,
                             criterion_options(r),
                             report.verdict.effect->effect);
  return kExitSuccess;
}

}  // namespace

void add_diagnose_command(CLI::App& app, CommandAction& action) {
  auto o = std::make_shared<DiagnoseOptions>();
  auto* cmd = app.add_subcommand("diagnose",
                                 "Compare a model with measurements, see where it fails, learn which physical effect is "
                                 "missing, add it and watch the error fall");
  diagnosis::DiagnoseRequest& r = o->request;
  cmd->add_option("--system", r.system, kSystemHelp)->required();
  cmd->add_option("--data", o->data, "Measurement file (.csv, .h5)")->required();
  cmd->add_option("--model", r.model_file, "Model file (TOML): preset, recalibrated parameters, effects");
  cmd->add_option("--preset", r.preset, "Preset without --model: sim or real")->capture_default_str();
  cmd->add_option("--add", r.add, "Add a library effect, EFFECT or EFFECT=VALUE (fitted without a value; repeatable)");
  cmd->add_flag("--auto", r.auto_select,
                "Add several effects in one call: the best set of up to 4 effects on held-out data (or --search "
                "forward), every set refitted jointly; --write-model writes the final model");
  cmd->add_option("--exclude", r.exclude,
                  "Leave candidate effects out of the ranking and the search: a name or a pattern (*, ?), e.g. "
                  "'param:*.armature' (repeatable)");
  cmd->add_option("--include", r.include,
                  "Rank and search candidates offered only on request too, e.g. 'param:*.second_moment_*' (the "
                  "bodies' second moments of mass; repeatable)");
  cmd->add_option("--search", r.search,
                  "With --auto: how it searches, subsets (every set of up to 4 effects; the default) or forward");
  cmd->add_flag("--json", o->json, "Print one JSON document on stdout instead of the report");
  writes_json(cmd->add_option("--out", o->out, "Write the HDF5 report here"));  // its report attribute is JSON
  cmd->add_option("--plots", o->plots, "Write PNG plots into this folder (needs matplotlib and h5py)");
  cmd->add_option("--write-model", o->write_model, "Write the improved model (TOML) for the next diagnosis");
  cmd->add_option("--integrator", r.integrator, "rk4 or euler")->capture_default_str();
  cmd->add_option("--heldout", r.heldout, "Fraction of the episodes held out (of the 10 blocks for a single-episode record)")->capture_default_str();
  cmd->add_option("--horizons", r.horizons, "Horizons k of the k-step predictions, comma-separated (e.g. 1,5,20)")
      ->capture_default_str()
      ->delimiter(',')
      ->check(integer_in(1, limits::kMaxHorizon));
  cmd->add_option("--gp-points", r.gp_points, "GP training points per state")
      ->capture_default_str()
      ->check(integer_in(2, limits::kMaxExactPoints));
  cmd->add_option("--gp-restarts", r.gp_restarts, "Random restarts of the GP fit")
      ->capture_default_str()
      ->check(integer_in(0, limits::kMaxRestarts));
  cmd->add_option("--backend", r.backend, "GP backend (exact, fitc, ssgp)")->capture_default_str();
  cmd->add_option("--seed", r.seed, "Seed of the GP subsample and restarts")
      ->capture_default_str()
      ->check(integer_in(0, static_cast<long long>(limits::kMaxSeed)));
  cmd->add_option("--criterion", r.criterion,
                  "Error the effects are fitted to and scored on: one-step; simulation over --window samples from "
                  "measured states (finds effects too small to see in one step, e.g. light damping); or "
                  "inverse-dynamics, the generalised-force residual (torque-sensing robots, measured velocities), or "
                  "inverse-dynamics-iv, its instrumental-variable form (IDIM-IV: no bias from noisy velocities)")
      ->capture_default_str();
  auto* window = cmd->add_option("--window", o->window,
                                 "Samples per simulation window, with --criterion simulation (e.g. a few periods of the "
                                 "slowest motion)")
                         ->check(integer_in(1, limits::kMaxHorizon));
  cmd->callback([&action, o, window] {
    if (window->count() > 0) o->request.window = o->window;
    action = [o] { return run_diagnose(*o); };
  });
}

}  // namespace gpilqg::cli
