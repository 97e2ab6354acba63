#include "run_session.hpp"

#include <iostream>
#include <sstream>

#include <fmt/format.h>

#include "commands/output_options.hpp"
#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg::cli {
namespace {

/// Deletes the checkpoints of a start that failed; the start's own error is the one to report.
void remove_checkpoints(std::vector<RunCheckpoint>& checkpoints) {
  for (auto& checkpoint : checkpoints) {
    try {
      checkpoint.remove();
    } catch (const std::exception&) {
    }
  }
}

/// Creates (or opens) every checkpoint; when creating one fails, the ones created before it go too,
/// so a failed start leaves nothing that a later start would take for an interrupted run.
/// `take_lock` false on the ranks that join the checkpoints rank 0 opened (and locked for the run).
std::vector<RunCheckpoint> open_all(const std::vector<CheckpointRequest>& requests, bool create, bool take_lock = true) {
  std::vector<RunCheckpoint> out;
  try {
    for (const auto& r : requests) {
      out.push_back(create ? RunCheckpoint::create(r.folder, *r.config, *r.options)
                           : RunCheckpoint::resume(r.folder, *r.config, *r.options, take_lock));
      remove_stale_temporaries_in(r.folder);  // of writes that a kill interrupted
    }
  } catch (...) {
    if (create) remove_checkpoints(out);
    throw;
  }
  return out;
}

}  // namespace

namespace {

/// Runs `step`; on an error, returns "<exit status>\n<message without \"error: \">".
std::string failure_of(const std::function<void()>& step, std::exception_ptr& error) {
  try {
    step();
    return "";
  } catch (...) {
    error = std::current_exception();
  }
  const DescribedError d = describe_error(error);
  return std::to_string(d.exit_status) + "\n" + d.detail;
}

}  // namespace

void every_rank_then_agree(const MpiSession& mpi, const std::function<void()>& step) {
  if (!mpi.distributed()) return step();
  std::exception_ptr error;
  const auto failed = mpi.first_error(failure_of(step, error));
  if (!failed) return;
  if (mpi.is_root() && error) std::rethrow_exception(error);
  const std::string& text = failed->second;
  const int status = std::stoi(text.substr(0, text.find('\n')));
  if (mpi.is_root()) {
    std::cerr << fmt::format("error: rank {} of {}: {}\n", failed->first, mpi.size(), text.substr(text.find('\n') + 1));
  }
  throw ReportedElsewhere(status);
}

void on_root_then_agree(const MpiSession& mpi, const std::function<void()>& step) {
  if (!mpi.distributed()) return step();
  std::exception_ptr error;
  const auto failed = mpi.first_error(mpi.is_root() ? failure_of(step, error) : "");
  if (!failed) return;
  if (error) std::rethrow_exception(error);
  throw ReportedElsewhere(std::stoi(failed->second.substr(0, failed->second.find('\n'))));
}

std::vector<RunCheckpoint> open_checkpoints(const MpiSession& mpi, const std::vector<CheckpointRequest>& requests,
                                            bool resume) {
  if (!mpi.distributed()) return open_all(requests, !resume);
  std::vector<RunCheckpoint> checkpoints;
  on_root_then_agree(mpi, [&] { checkpoints = open_all(requests, !resume); });
  std::string error;
  if (!mpi.is_root()) {
    try {
      checkpoints = open_all(requests, false, false);
    } catch (const std::exception& e) {
      error = fmt::format("rank {} on {} cannot open the checkpoint rank 0 prepared ({}); the result's folder must be on a "
                          "file system that every rank sees",
                          mpi.rank(), mpi.host(), e.what());
    }
  }
  if (const auto failed = mpi.first_error(error)) {
    if (mpi.is_root() && !resume) remove_checkpoints(checkpoints);  // a start that failed leaves nothing in the way
    if (mpi.is_root()) throw InputError(failed->second);
    throw ReportedElsewhere(kExitBadInput);
  }
  return checkpoints;
}

int unit_threads(const MpiSession& mpi, int option) {
  if (option > 0) return option;
  return mpi.distributed() ? mpi.threads_per_rank() : RunOptions{}.threads;
}

void print_unit_times(const Distribution& distribution, int ranks) {
  std::vector<double> busy(static_cast<std::size_t>(ranks), 0.0);
  std::vector<int> count(static_cast<std::size_t>(ranks), 0);
  for (std::size_t i = 0; i < distribution.ranks.size(); ++i) {
    const int r = distribution.ranks[i];
    if (r < 0) continue;
    busy[static_cast<std::size_t>(r)] += distribution.seconds[i];
    ++count[static_cast<std::size_t>(r)];
  }
  for (int r = 0; r < ranks; ++r)
    std::cerr << fmt::format("rank {}: {} units, {:.1f} s of work\n", r, count[static_cast<std::size_t>(r)],
                             busy[static_cast<std::size_t>(r)]);
}

std::optional<int> unfinished_exit_status(const MpiSession& mpi, const DistributedRuns& runs,
                                          const std::filesystem::path& checkpoint, int interrupted_status) {
  const Distribution& d = runs.distribution;
  switch (d.outcome) {
    case Distribution::Outcome::Finished:
      return std::nullopt;
    case Distribution::Outcome::Interrupted:
      if (mpi.is_root())
        std::cerr << fmt::format("interrupted: every rank stopped at its next iteration boundary; progress is in {}\n"
                                 "continue with the same command and --resume\n",
                                 checkpoint.string());
      return interrupted_status;
    case Distribution::Outcome::Failed: {
      if (!mpi.is_root()) return d.failure_exit;
      std::cerr << fmt::format("error: rank {} of {} failed on {}: {}\nthe other ranks stopped at their next iteration "
                               "boundary; all finished work is in {}; fix the cause and continue with --resume\n",
                               d.failed_rank, mpi.size(), runs.failed_unit, d.failure, checkpoint.string());
      return d.failure_exit;
    }
  }
  return std::nullopt;
}

}  // namespace gpilqg::cli
