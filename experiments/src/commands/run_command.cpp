/// `gpilqg run cartpole|quadrotor [--config F] [--seeds N] [--iterations K] [--backends LIST] [--out F.h5]
/// [--plots DIR] [--resume]`: the paper's experiments (run_experiment.hpp), results in HDF5 (run_results_io.hpp),
/// figures by experiments/plots/plot_run.py.

#include <cmath>
#include <cstdlib>
#include <iostream>

#include <fmt/format.h>

#include "commands.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "stop_signal.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/plot_script.hpp"
#include "gpilqg/experiments/run_checkpoint.hpp"
#include "gpilqg/experiments/run_results_io.hpp"

namespace gpilqg::cli {
namespace {

struct RunArguments {
  std::string system;
  std::string config;
  int seeds = 1;
  std::uint64_t first_seed = 1;
  int iterations = -1;
  std::string backends;
  std::string out;
  std::string plots;
  bool no_plots = false;
  bool resume = false;
};

/// Mean and standard deviation over seeds of each iteration's normalised cost, one line per algorithm.
void print_summary(const RunResults& results) {
  for (std::size_t t = 0; t < results.tasks.size(); ++t) {
    const TaskResults& task = results.tasks[t];
    std::cout << fmt::format("\n{} (normalised cost: mean over {} seed(s) of cost / ilqg_real's; iterations 0..{})\n",
                             results.config.tasks[t].name, task.seeds.size(), results.config.iterations);
    std::size_t reference = 0;
    for (std::size_t a = 0; a < task.algorithms.size(); ++a)
      if (task.algorithms[a] == "ilqg_real") reference = a;
    for (std::size_t a = 0; a < task.algorithms.size(); ++a) {
      std::string line = fmt::format("  {:<16}", task.algorithms[a]);
      const std::size_t K = task.seeds.front()[a].iterations.size();
      for (std::size_t k = 0; k < K; ++k) {
        double sum = 0.0, sum2 = 0.0;
        for (const auto& runs : task.seeds) {
          const double ratio = runs[a].iterations[k].evaluation.mean_cost / runs[reference].iterations[k].evaluation.mean_cost;
          sum += ratio, sum2 += ratio * ratio;
        }
        const double S = static_cast<double>(task.seeds.size());
        const double mean = sum / S, spread = std::sqrt(std::max(0.0, sum2 / S - mean * mean));
        line += task.seeds.size() > 1 ? fmt::format(" {:7.3f}±{:<5.3f}", mean, spread) : fmt::format(" {:7.3f}", mean);
      }
      std::cout << line << '\n';
    }
  }
}

int run_command(const RunArguments& a) {
  const std::filesystem::path out = a.out.empty() ? std::filesystem::path("out") / ("run_" + a.system + ".h5") : std::filesystem::path(a.out);
  check_output_file_option("--out", out);
  if (!a.no_plots) check_output_folder_option("--plots", a.plots);
  if (a.first_seed + static_cast<std::uint64_t>(a.seeds) - 1 > limits::kMaxSeed)
    throw InputError(fmt::format("--first-seed {} --seeds {}: the last seed exceeds {} (the largest seed)", a.first_seed, a.seeds,
                                 limits::kMaxSeed));
  RunConfig config = load_run_config(a.system, a.config.empty() ? std::nullopt : std::optional<std::filesystem::path>(a.config));
  if (a.iterations > 0) config.iterations = a.iterations;  // validated by its option check
  RunOptions options;
  options.seeds.clear();
  for (int s = 0; s < a.seeds; ++s) options.seeds.push_back(a.first_seed + static_cast<std::uint64_t>(s));
  if (!a.backends.empty()) {
    try {
      options.backends = gp::parse_backend_list(a.backends);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("--backends: {}", e.what()));
    }
  }
  options.progress = [](const std::string& line) { std::cerr << line << std::endl; };
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());

  // Every completed iteration goes to the checkpoint folder beside the result (run_checkpoint.hpp);
  // Ctrl-C stops at the next iteration boundary, leaving any previous result file as it was.
  const std::filesystem::path folder = RunCheckpoint::folder_for(out);
  RunCheckpoint checkpoint = a.resume ? RunCheckpoint::resume(folder, config, options) : RunCheckpoint::create(folder, config, options);
  remove_stale_temporaries_in(folder);
  const StopSignalGuard stop_signal;
  checkpoint.set_stop_requested(&StopSignalGuard::stop_requested);
  options.journal = &checkpoint;
  RunResults results;
  try {
    results = run_experiment(config, options);
  } catch (const RunInterrupted& e) {
    std::cerr << fmt::format("interrupted: {}\n{}continue with the same command and --resume\n", e.what(),
                             std::filesystem::exists(out) ? fmt::format("{} is unchanged; ", out.string()) : "");
    return kExitSignalBase + StopSignalGuard::signal_number();
  }
  write_run_results(out, results);
  checkpoint.remove();
  print_summary(results);
  std::cout << fmt::format("\nresults: {}\n", out.string());
  if (a.no_plots) return kExitSuccess;
  const std::filesystem::path plots = figures_folder(out, a.plots);
  run_plot_script("plot_run.py", out, plots);
  std::cout << fmt::format("figures: {}\n", plots.string());
  return kExitSuccess;
}

}  // namespace

void add_run_command(CLI::App& app, CommandAction& action) {
  auto args = std::make_shared<RunArguments>();
  auto* cmd = app.add_subcommand("run", "Run the paper's experiment for a system: ilqg_real, ilqg_sim, gp_ilqg and pddp "
                                        "side by side over seeds; results in HDF5, figures as PNG");
  cmd->add_option("SYSTEM", args->system, kSystemHelp)
      ->required();
  cmd->add_option("--config", args->config, "TOML file overriding the embedded defaults (experiments/configs/run_SYSTEM.toml)");
  cmd->add_option("--seeds", args->seeds, "number of seeds (default 1)")->check(integer_in(1, limits::kMaxSeeds));
  cmd->add_option("--first-seed", args->first_seed, "the first seed (default 1); seeds are consecutive")
      ->check(integer_in(0, static_cast<long long>(limits::kMaxSeed)));
  cmd->add_option("--iterations", args->iterations, "cap on GP-ILQG iterations per task (overrides loop.iterations)")
      ->check(integer_in(1, limits::kMaxLoopIterations));
  cmd->add_option("--backends", args->backends, "compare GP backends inside the loop, e.g. exact,fitc,ssgp");
  cmd->add_option("--out", args->out, "result file (default out/run_SYSTEM.h5)");
  cmd->add_option("--plots", args->plots, "folder for the PNG figures (default: beside the result)");
  cmd->add_flag("--no-plots", args->no_plots, "write the result only");
  cmd->add_flag("--resume", args->resume, "continue an interrupted run from OUT.checkpoint/ (same arguments as the "
                                          "interrupted run); the result equals an uninterrupted run's");
  cmd->callback([&action, args] { action = [args] { return run_command(*args); }; });
}

}  // namespace gpilqg::cli
