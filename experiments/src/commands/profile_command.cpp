/// `gpilqg profile DATA --backends LIST [--sizes LIST] [--json] [--out F.h5] [--plots DIR] [...]`:
/// every GP backend on growing subsets of a data set, timed and scored (profile.hpp).

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "option_checks.hpp"
#include "output_options.hpp"
#include "parallel/mpi_session.hpp"
#include "parallel/run_session.hpp"
#include "parallel/unit_distribution.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/profile.hpp"

namespace gpilqg::cli {

namespace {

struct ProfileCommandOptions {
  std::string file;
  std::string backends;
  std::string sizes = "all";
  bool json = false;
  std::string out;
  std::string plots;
  ProfileDataOptions data;
  std::string target = "residual";
  std::string start = "data";
  int restarts = 0;
  int max_evaluations = 100;
  std::uint64_t seed = 1;
  int max_test = 0;
  double memory_budget_gb = 4.0;
  double time_budget = ProfileOptions{}.time_budget_seconds;
  gp::BackendSettings settings;
  bool threads_given = false;  ///< --threads on the command line (else under MPI: each rank's share)
};

/// Rough relative cost of a row, for the order in which ranks take them (unit_scheduler.hpp): the
/// dense exact GP grows as N^3, the approximations about linearly.
double expected_cost(const ProfileCase& c) {
  const double n = c.size / 1000.0;
  return 1e-3 + (c.backend.rfind("exact", 0) == 0 ? n * n * n : n);
}

/// The rows on every rank of `mpirun` (or in order in one process); rank 0 gets them all, in report
/// order; the other ranks get nothing.
std::vector<ProfileRow> profile_rows(const MpiSession& mpi, const std::filesystem::path& file, const ProfileData& data,
                                     const ProfileOptions& options, const std::function<void(const ProfileRow&)>& progress) {
  const std::vector<ProfileCase> cases = profile_cases(data, options);
  std::vector<double> weights;
  for (const auto& c : cases) weights.push_back(expected_cost(c));
  UnitScheduler scheduler(std::vector<std::vector<int>>(cases.size()), weights);
  const UnitWork work = [&](int index, const std::function<bool()>&) {
    ProfileRow row = run_profile_case(file, data, options, cases[static_cast<std::size_t>(index)]);
    progress(row);
    return profile_row_bytes(row);
  };
  const Distribution d = distribute_units(mpi, scheduler, work, [] { return false; });
  if (d.outcome == Distribution::Outcome::Failed) {
    if (!mpi.is_root()) throw ReportedElsewhere(d.failure_exit);
    const ProfileCase& c = cases.at(static_cast<std::size_t>(d.failed_unit));
    const std::string message = fmt::format("rank {} of {} failed on backend '{}', N = {}: {}", d.failed_rank, mpi.size(),
                                            c.backend, c.size, d.failure);
    if (d.failure_exit == kExitBadInput) throw InputError(message);
    throw std::runtime_error(message);
  }
  std::vector<ProfileRow> rows;
  if (mpi.is_root())
    for (const auto& bytes : d.payloads) rows.push_back(profile_row_from_bytes(bytes));
  return rows;
}

/// "1000, 5000,all" -> {1000, 5000, 0}; InputError naming the entry.
std::vector<int> parse_sizes(const std::string& list) {
  std::vector<int> sizes;
  std::size_t start = 0;
  while (true) {
    const auto comma = list.find(',', start);
    std::string entry = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    entry.erase(0, entry.find_first_not_of(" \t"));
    entry.erase(entry.find_last_not_of(" \t") + 1);
    if (entry == "all") {
      sizes.push_back(0);
    } else {
      std::size_t used = 0;
      int value = 0;
      try {
        value = std::stoi(entry, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != entry.size() || entry.empty() || value < 1)
        throw InputError(fmt::format("--sizes '{}': entry '{}' is not a positive integer or 'all'", list, entry));
      if (value > limits::kMaxSamples)
        throw InputError(fmt::format("--sizes '{}': entry {} exceeds {} (the sample limit)", list, value, limits::kMaxSamples));
      sizes.push_back(value);
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return sizes;
}

int run_profile_command(ProfileCommandOptions& o) {
  const MpiSession mpi;
  ProfileOptions options;
  ProfileData data;
  every_rank_then_agree(mpi, [&] {
    check_output_file_option("--out", o.out, {"profile writes an HDF5 result file", kHdf5Extensions},
                             {{"DATA", o.file}, system_input(o.data.system)});
    check_output_folder_option("--plots", o.plots);
    if (o.target == "residual")
      o.data.target = ProfileTarget::Residual;
    else if (o.target == "increment")
      o.data.target = ProfileTarget::Increment;
    else
      throw InputError("--target '" + o.target + "': expected 'residual' or 'increment'");
    try {
      options.backends = gp::parse_backend_list(o.backends);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--backends: ") + e.what());
    }
    options.sizes = parse_sizes(o.sizes);
    options.settings = o.settings;
    options.fit.restarts = o.restarts;
    options.fit.max_evaluations = o.max_evaluations;
    options.fit.seed = o.seed;
    options.memory_budget_bytes = o.memory_budget_gb * static_cast<double>(1ull << 30);
    options.time_budget_seconds = o.time_budget;
    if (o.max_test > 0) options.max_test_points = o.max_test;
    if (o.start != "data" && o.start != "reference")
      throw InputError("--start '" + o.start + "': expected 'data' or 'reference'");
    options.start_from_reference = o.start == "reference";
    data = read_profile_data(o.file, o.data);
    options.validate(data);
  });
  if (mpi.distributed() && !o.threads_given) options.settings.threads = mpi.threads_per_rank();
  const std::string rank_prefix = mpi.distributed() ? fmt::format("[rank {}] ", mpi.rank()) : "";
  ProfileReport report = profile_report_header(o.file, data, options);
  report.rows = profile_rows(mpi, o.file, data, options, [&](const ProfileRow& row) {
    std::cerr << fmt::format("{}profile: {} N={} {} fit {:.3f} s, predict {:.3f} s{}\n", rank_prefix, row.backend, row.size,
                             row.status, row.fit_seconds, row.predict_seconds, row.reason.empty() ? "" : " (" + row.reason + ")");
  });
  if (!mpi.is_root()) return kExitSuccess;
  std::filesystem::path h5 = o.out;
  if (!o.out.empty()) write_profile_hdf5(o.out, report);
  if (!o.plots.empty()) {
    if (h5.empty()) {
      std::filesystem::create_directories(o.plots);
      h5 = std::filesystem::path(o.plots) / "profile.h5";
      write_profile_hdf5(h5, report);
    }
    plot_profile(h5, o.plots);
  }
  if (o.json)
    std::cout << profile_json(report).dump(2) << '\n';
  else
    std::cout << format_profile(report);
  return kExitSuccess;
}

}  // namespace

void add_profile_command(CLI::App& app, CommandAction& action) {
  CLI::App* cmd = app.add_subcommand(
      "profile",
      "Train GP backends on growing subsets of a data set; report fit and prediction time and the test "
      "scores SMSE, MNLP, MSLL");
  auto o = std::make_shared<ProfileCommandOptions>();
  cmd->add_option("DATA", o->file,
                  "Benchmark HDF5 (X_train, y_train, X_test, y_test[, reference_hyperparameters]) or a "
                  "measurement set (.csv / .h5 with /episodes; needs --system)")
      ->required();
  cmd->add_option("--backends", o->backends, "Comma-separated backends: " + fmt::format("{}", fmt::join(gp::backend_names(), ", ")))
      ->required();
  cmd->add_option("--sizes", o->sizes, "Comma-separated training-set sizes, 'all' for the whole set (nested subsets)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print one JSON document on stdout instead of the table");
  cmd->add_option("--out", o->out, "Write the results to this HDF5 file (temporary file, then renamed)");
  cmd->add_option("--plots", o->plots, "Write profile_pareto.png (accuracy against time) into this folder");
  cmd->add_option("--restarts", o->restarts, "Random restarts per fit")
      ->capture_default_str()
      ->check(integer_in(0, limits::kMaxRestarts));
  cmd->add_option("--max-evaluations", o->max_evaluations, "NLML evaluations per start")
      ->capture_default_str()
      ->check(integer_in(1, limits::kMaxEvaluations));
  cmd->add_option("--start", o->start,
                  "'data': fits start from data-driven values (and restarts); 'reference': also from the data "
                  "set's reference hyperparameters, tried first")
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the subsets and the restarts")
      ->capture_default_str()
      ->check(integer_in(0, static_cast<long long>(limits::kMaxSeed)));
  cmd->add_option("--max-test", o->max_test, "Score on this many test points (a fixed random subset; 0: all)")
      ->capture_default_str()
      ->check(integer_in(0, limits::kMaxSamples));
  cmd->add_option("--memory-budget-gb", o->memory_budget_gb,
                  "Skip rows whose matrices exceed this (exact: 16 N^2 bytes fitted, 8 N^2 conditioned; FITC and SSGP: "
                  "their N x M and M x M matrices)")
      ->capture_default_str()
      ->check(number_in(0.0, 1e6, true));
  cmd->add_option("--time-budget", o->time_budget,
                  "Seconds per row (backend x size): skip rows whose predicted fit + prediction time (flop count at "
                  "this machine's measured rate) exceeds this, stop fits that pass it at their best point; 0: none")
      ->capture_default_str()
      ->check(number_in(0.0, 1e9));
  cmd->add_option("--inducing", o->settings.inducing, "fitc: pseudo-inputs M")
      ->capture_default_str()
      ->check(integer_in(1, limits::kMaxInducing));
  cmd->add_option("--frequencies", o->settings.frequencies, "ssgp: spectral points m")
      ->capture_default_str()
      ->check(integer_in(1, limits::kMaxFrequencies));
  cmd->add_option("--compact-neighbours", o->settings.compact_neighbours,
                  "compact: neighbours per point at the start of the fit")
      ->capture_default_str()
      ->check(integer_in(1, limits::kMaxNeighbours));
  cmd->add_option("--compact-max-neighbours", o->settings.compact_max_neighbours,
                  "compact: each support radius may grow by this / --compact-neighbours during the fit")
      ->capture_default_str()
      ->check(integer_in(1, limits::kMaxNeighbours));
  cmd->add_option("--threads", o->settings.threads, "Threads inside one fit (under MPI default: each rank's share of its machine)")
      ->capture_default_str()
      ->check(integer_in(1, limits::kMaxThreads));
  cmd->add_option("--system", o->data.system, std::string("Measurement sets: the system. ") + kSystemHelp);
  cmd->add_option("--output", o->data.output, "Measurement sets: the state whose target is learned (default: the first)");
  cmd->add_option("--target", o->target,
                  "Measurement sets: 'residual' (x' - simulator step, the 'sim' preset, RK4 or the model's own integrator) or 'increment' (x' - x)")
      ->capture_default_str();
  cmd->add_option("--test-every", o->data.test_every, "Measurement sets: every k-th sample is held out for testing")
      ->capture_default_str()
      ->check(integer_in(2, limits::kMaxSamples));
  cmd->callback([o, cmd, &action] {
    o->threads_given = cmd->count("--threads") > 0;
    action = [o] { return run_profile_command(*o); };
  });
}

}  // namespace gpilqg::cli
