/// `gpilqg sweep SWEEP.toml [--out F.h5] [--plots DIR] [--no-plots] [--resume] [--threads N]`: a grid
/// of run configs times seeds (sweep_config.hpp), every unit of every grid point spread over the
/// ranks of `mpirun` (distributed_run.hpp), or run one after another in a single process. One result
/// file with a group per grid point (sweep_results_io.hpp) and a summary figure (plot_sweep.py).

#include <algorithm>
#include <cmath>
#include <iostream>

#include <fmt/format.h>

#include "commands.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "parallel/mpi_session.hpp"
#include "parallel/run_session.hpp"
#include "stop_signal.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/plot_script.hpp"
#include "gpilqg/experiments/sweep_results_io.hpp"

namespace gpilqg::cli {
namespace {

struct SweepArguments {
  std::string file;
  std::string out;
  std::string plots;
  bool no_plots = false;
  bool resume = false;
  int threads = 0;
};

/// Per grid point and task: gp_ilqg's normalised cost at the last iteration, mean and spread over seeds.
void print_summary(const SweepConfig& sweep, const std::vector<RunResults>& results) {
  std::cout << fmt::format("\n{} grid points x {} seed(s); gp_ilqg's normalised cost at the last iteration "
                           "(mean ± std over seeds):\n",
                           sweep.points.size(), sweep.seeds.size());
  for (std::size_t p = 0; p < results.size(); ++p) {
    std::string line = fmt::format("  point {:<3} {:<50}", p, sweep.points[p].label());
    for (const TaskResults& task : results[p].tasks) {
      std::size_t gp = 0, reference = 0;
      for (std::size_t a = 0; a < task.algorithms.size(); ++a) {
        if (task.algorithms[a].rfind("gp_ilqg", 0) == 0 && gp == 0) gp = a;
        if (task.algorithms[a] == "ilqg_real") reference = a;
      }
      double sum = 0.0, sum2 = 0.0;
      for (const auto& runs : task.seeds) {
        const double r = runs[gp].iterations.back().evaluation.mean_cost / runs[reference].iterations.back().evaluation.mean_cost;
        sum += r, sum2 += r * r;
      }
      const double S = static_cast<double>(task.seeds.size()), mean = sum / S;
      line += fmt::format(" {:7.3f}±{:<5.3f}", mean, std::sqrt(std::max(0.0, sum2 / S - mean * mean)));
    }
    std::cout << line << '\n';
  }
}

int sweep_command(const SweepArguments& a) {
  const MpiSession mpi;
  SweepConfig sweep;
  std::filesystem::path out;
  every_rank_then_agree(mpi, [&] {
    sweep = load_sweep_config(a.file);
    out = a.out.empty() ? sweep.out : std::filesystem::path(a.out);
    check_output_file_option(a.out.empty() ? "out (in the sweep file)" : "--out", out,
                             {"sweep writes an HDF5 result file", kHdf5Extensions},
                             {{"SWEEP", a.file},
                              {"config (in the sweep file)", sweep.config},
                              system_input(sweep.system, "system (in the sweep file)")});
    if (!a.no_plots) check_output_folder_option("--plots", a.plots);
  });
  const std::string rank_prefix = mpi.distributed() ? fmt::format("[rank {}] ", mpi.rank()) : "";
  const int threads = unit_threads(mpi, a.threads);

  // One checkpoint per grid point in "<out>.checkpoint/point-<p>/" (run_checkpoint.hpp).
  const std::filesystem::path folder = RunCheckpoint::folder_for(out);
  std::vector<RunOptions> options(sweep.points.size());
  std::vector<CheckpointRequest> requests;
  for (std::size_t p = 0; p < sweep.points.size(); ++p) {
    options[p].seeds = sweep.seeds;
    options[p].threads = threads;
    const std::string prefix = fmt::format("{}[point {}] ", rank_prefix, p);
    options[p].progress = [prefix](const std::string& line) { std::cerr << prefix + line + "\n" << std::flush; };
    requests.push_back({folder / fmt::format("point-{}", p), &sweep.points[p].config, &options[p]});
  }
  bool folder_existed = false;
  on_root_then_agree(mpi, [&] {
    if (!a.no_plots) require_plotting("plot_sweep.py");  // before the work, not after
    if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
    folder_existed = std::filesystem::exists(folder);
    if (!a.resume && folder_existed && !std::filesystem::is_empty(folder))
      throw InputError(fmt::format("{}: a checkpoint of an interrupted sweep is in the way; continue that sweep with --resume, "
                                   "or delete the folder to start over",
                                   folder.string()));
  });
  std::vector<RunCheckpoint> checkpoints;
  try {
    checkpoints = open_checkpoints(mpi, requests, a.resume);
  } catch (...) {
    std::error_code ignored;
    if (mpi.is_root() && !folder_existed) std::filesystem::remove(folder, ignored);  // only when empty
    throw;
  }
  const StopSignalGuard stop_signal;
  std::vector<RunPart> parts;
  for (std::size_t p = 0; p < sweep.points.size(); ++p) {
    options[p].journal = &checkpoints[p];
    parts.push_back({&sweep.points[p].config, options[p], &checkpoints[p], fmt::format("grid point {}", p)});
  }
  DistributedRuns runs;
  try {
    runs = run_distributed(mpi, parts, &StopSignalGuard::stop_requested);
  } catch (const RunInterrupted& e) {  // one process: the unit stopped at its iteration boundary
    std::cerr << fmt::format("interrupted: {}\ncontinue with the same command and --resume\n", e.what());
    return StopSignalGuard::exit_status();
  }
  if (const auto status = unfinished_exit_status(mpi, runs, folder, StopSignalGuard::exit_status())) return *status;
  if (!mpi.is_root()) return kExitSuccess;
  if (mpi.distributed()) print_unit_times(runs.distribution, mpi.size());
  write_sweep_results(out, sweep, runs.results);
  for (auto& checkpoint : checkpoints) checkpoint.remove();
  std::error_code ignored;
  std::filesystem::remove(folder, ignored);  // empty now
  print_summary(sweep, runs.results);
  print_result_and_draw_figures("plot_sweep.py", out, a.plots, a.no_plots);
  return kExitSuccess;
}

}  // namespace

void add_sweep_command(CLI::App& app, CommandAction& action) {
  auto args = std::make_shared<SweepArguments>();
  auto* cmd = app.add_subcommand("sweep", "Run a grid of run configs x seeds (SWEEP.toml, docs/cluster.md), spread over the "
                                          "ranks when launched by mpirun; one HDF5 file with a group per grid point");
  cmd->add_option("SWEEP", args->file, "the sweep file: system, seeds and a [grid] of run config fields")->required();
  cmd->add_option("--out", args->out, "result file (default: the sweep file's `out`, else SWEEP.h5 beside it)");
  cmd->add_option("--plots", args->plots, "folder for the summary figure sweep_cost.png (default: beside the result)");
  cmd->add_flag("--no-plots", args->no_plots, "write the result only");
  cmd->add_flag("--resume", args->resume, "continue an interrupted sweep from OUT.checkpoint/ (the same sweep file)");
  cmd->add_option("--threads", args->threads, "threads inside one unit of work (default 2; under MPI each rank's share of "
                                              "its machine's cores); results do not depend on it")
      ->check(integer_in(1, 1024));
  cmd->callback([&action, args] { action = [args] { return sweep_command(*args); }; });
}

}  // namespace gpilqg::cli
