/// `gpilqg run cartpole|quadrotor [--config F] [--seeds N] [--iterations K] [--backends LIST] [--out F.h5]
/// [--plots DIR] [--resume] [--threads N]`: the paper's experiments (run_experiment.hpp), results in HDF5
/// (run_results_io.hpp), figures by experiments/plots/plot_run.py. Under `mpirun -np K` the run's units
/// are spread over the ranks (parallel/distributed_run.hpp) and the result file is the same.

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <optional>

#include <fmt/format.h>

#include "commands.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "parallel/mpi_session.hpp"
#include "parallel/run_session.hpp"
#include "stop_signal.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/systems.hpp"
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
  std::optional<std::string> backends;  ///< nullopt when --backends is not given; given, it may not be empty
  std::string out;
  std::string plots;
  bool no_plots = false;
  bool resume = false;
  int threads = 0;  ///< 0: 2 in one process, each rank's share of its machine under MPI
};

/// Mean and standard deviation over seeds of each iteration's normalised cost, one line per algorithm.
void print_summary(const RunResults& results) {
  for (std::size_t t = 0; t < results.tasks.size(); ++t) {
    const TaskResults& task = results.tasks[t];
    std::cout << fmt::format("\n{} (normalised cost, cost / ilqg_real's: mean±std over {} seed(s); iterations 0..{})\n",
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
    for (std::size_t a = 0; a < task.algorithms.size(); ++a)
      for (std::size_t s = 0; s < task.seeds.size(); ++s)
        if (const auto& d = task.seeds[s][a].diagnosis)
          std::cout << fmt::format("  {} diagnosis, seed {}: {}\n", task.algorithms[a], results.options.seeds[s],
                                   diagnosis_summary(*d));
  }
}

int run_command(const RunArguments& a) {
  const MpiSession mpi;
  const std::filesystem::path out = a.out.empty() ? std::filesystem::path("out") / ("run_" + a.system + ".h5") : std::filesystem::path(a.out);
  RunConfig config;
  RunOptions options;
  every_rank_then_agree(mpi, [&] {
    check_output_file_option("--out", out, {"run writes an HDF5 result file", kHdf5Extensions},
                             {system_input(a.system, "SYSTEM"), {"--config", a.config}});
    if (!a.no_plots) check_output_folder_option("--plots", a.plots);
    if (a.first_seed + static_cast<std::uint64_t>(a.seeds) - 1 > limits::kMaxSeed)
      throw InputError(fmt::format("--first-seed {} --seeds {}: the last seed exceeds {} (the largest seed)", a.first_seed,
                                   a.seeds, limits::kMaxSeed));
    if (system_signature(a.system).controls.empty()) throw InputError(passive_system_refusal(a.system));
    config = load_run_config(a.system, a.config.empty() ? std::nullopt : std::optional<std::filesystem::path>(a.config));
    if (a.iterations > 0) config = with_iterations(std::move(config), a.iterations, "--iterations");
    options.seeds.clear();
    for (int s = 0; s < a.seeds; ++s) options.seeds.push_back(a.first_seed + static_cast<std::uint64_t>(s));
    if (a.backends) {
      try {
        options.backends = gp::parse_backend_list(*a.backends);
      } catch (const std::invalid_argument& e) {
        throw InputError(fmt::format("--backends: {}", e.what()));
      }
    }
  });
  options.threads = unit_threads(mpi, a.threads);
  const std::string rank_prefix = mpi.distributed() ? fmt::format("[rank {}] ", mpi.rank()) : "";
  options.progress = [rank_prefix](const std::string& line) { std::cerr << rank_prefix + line + "\n" << std::flush; };
  on_root_then_agree(mpi, [&] {
    if (!a.no_plots) require_plotting("plot_run.py");  // before the work, not after
    if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  });

  // Every completed iteration goes to the checkpoint folder beside the result (run_checkpoint.hpp);
  // Ctrl-C stops at the next iteration boundary, leaving any previous result file as it was.
  const std::filesystem::path folder = RunCheckpoint::folder_for(out);
  RunCheckpoint checkpoint = std::move(open_checkpoints(mpi, {{folder, &config, &options}}, a.resume).front());
  const StopSignalGuard stop_signal;
  checkpoint.set_stop_requested(&StopSignalGuard::stop_requested);
  options.journal = &checkpoint;
  const auto interrupted = [&](const std::string& what) {
    std::cerr << fmt::format("interrupted: {}\n{}continue with the same command and --resume\n", what,
                             std::filesystem::exists(out) ? fmt::format("{} is unchanged; ", out.string()) : "");
    return StopSignalGuard::exit_status();
  };
  RunResults results;
  if (!mpi.distributed()) {
    try {
      results = run_experiment(config, options);
    } catch (const RunInterrupted& e) {
      return interrupted(e.what());
    }
  } else {
    DistributedRuns run = run_distributed(mpi, {{&config, options, &checkpoint, ""}}, &StopSignalGuard::stop_requested);
    if (const auto status = unfinished_exit_status(mpi, run, folder, StopSignalGuard::exit_status())) return *status;
    if (!mpi.is_root()) return kExitSuccess;
    print_unit_times(run.distribution, mpi.size());
    results = std::move(run.results.front());
  }
  write_run_results(out, results);
  checkpoint.remove();
  print_summary(results);
  print_result_and_draw_figures("plot_run.py", out, a.plots, a.no_plots);
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
  cmd->add_option("--threads", args->threads, "threads inside one unit of work (default 2; under MPI each rank's share of "
                                             "its machine's cores); results do not depend on it")
      ->check(integer_in(1, 1024));
  cmd->add_flag("--resume", args->resume, "continue an interrupted run from OUT.checkpoint/ (same arguments as the "
                                          "interrupted run); the result equals an uninterrupted run's");
  cmd->callback([&action, args] { action = [args] { return run_command(*args); }; });
}

}  // namespace gpilqg::cli
