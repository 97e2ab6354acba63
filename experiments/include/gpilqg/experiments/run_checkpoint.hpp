#pragma once
/// @file run_checkpoint.hpp
/// Resumable `gpilqg run` (docs/reliability.md). While a run works, its checkpoint folder
/// "<result>.checkpoint/" beside the result file holds
///
///   manifest.h5                          what the run is: attrs format_version, system, config (the full
///                                        TOML), model_files (the texts of the files it names),
///                                        iterations, seeds, backends
///   lock                                 the pid of the run working in the folder, locked while it
///                                        works (checkpoint_lock.hpp): a second run on it is refused
///   seed-<s>_task-<t>_<algorithm>.h5     one algorithm on one task and seed after its last completed
///                                        iteration: every IterationRecord (policy, prediction, evaluation,
///                                        timings, GP hyperparameters), the collected data, converged_at,
///                                        and the last GP-ILQG residual model (gp_io layout, under /model)
///
/// Each file is replaced atomically (atomic_file.hpp) after every completed iteration, so an
/// interruption at any moment leaves the state of the last completed iteration. `--resume` restores
/// each algorithm from its file and continues with the next iteration. Everything random is drawn from
/// streams fixed by (seed, task, purpose, iteration) (run_setup.hpp) and the GP of the last iteration is
/// restored exactly (conditioning is deterministic, gp_io.hpp), so the resumed run computes the same
/// numbers as an uninterrupted one; only wall-clock times of the re-run work differ, and the solver's
/// per-iteration trace (not part of the result file) is not kept.
///
/// Interruption: `save` calls `stop_requested` after each file is written and throws RunInterrupted
/// when it answers true (the CLI sets it on SIGINT or SIGTERM), so a run stops at an iteration boundary
/// with everything up to it saved; the result file is written only when the whole run completes.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpilqg/experiments/run_experiment.hpp"

namespace gpilqg {

class CheckpointLock;

/// Thrown by RunCheckpoint::save when a stop was requested; what() says what was saved.
class RunInterrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class RunCheckpoint final : public RunJournal {
 public:
  /// "<result>.checkpoint" beside the result file.
  static std::filesystem::path folder_for(const std::filesystem::path& result_file);

  /// Starts an empty checkpoint in `folder` for this run and takes its lock (checkpoint_lock.hpp),
  /// held by this object and its copies until remove() or the last of them goes. Throws
  /// std::invalid_argument when `folder` holds an interrupted run (resume it or delete it) or another
  /// run holds the lock ("in use by pid N"), std::runtime_error when it cannot be created.
  static RunCheckpoint create(const std::filesystem::path& folder, const RunConfig& config, const RunOptions& options);
  /// Opens the checkpoint of an interrupted run and takes its lock; `take_lock` false for the ranks of
  /// an MPI run that join the checkpoint rank 0 opened (rank 0 holds the lock for the run). Throws
  /// std::invalid_argument when there is none, when another run holds the lock, or when it was made
  /// for a different run (naming the field that differs: system, config, the files it names,
  /// iterations, seeds or backends); std::runtime_error when the manifest cannot be read.
  static RunCheckpoint resume(const std::filesystem::path& folder, const RunConfig& config, const RunOptions& options,
                              bool take_lock = true);

  const std::filesystem::path& folder() const { return folder_; }
  /// Asked after every save; true makes save throw RunInterrupted.
  void set_stop_requested(std::function<bool()> stop_requested) { stop_requested_ = std::move(stop_requested); }
  /// Number of algorithm runs restored so far (for the progress line of a resumed run).
  int restored_count() const { return restored_; }

  std::optional<AlgorithmRun> restore(const TaskContext& context, std::uint64_t seed, const std::string& name) const override;
  void save(const TaskContext& context, std::uint64_t seed, const AlgorithmRun& run) override;

  /// Deletes the folder (after the result file has been written).
  void remove();

 private:
  RunCheckpoint(std::filesystem::path folder, std::shared_ptr<CheckpointLock> lock)
      : folder_(std::move(folder)), lock_(std::move(lock)) {}
  std::filesystem::path unit_file(const TaskContext& context, std::uint64_t seed, const std::string& name) const;

  std::filesystem::path folder_;
  std::shared_ptr<CheckpointLock> lock_;  ///< null for an MPI rank that joined rank 0's checkpoint
  std::function<bool()> stop_requested_;
  mutable int restored_ = 0;
};

}  // namespace gpilqg
