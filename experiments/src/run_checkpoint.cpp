#include "gpilqg/experiments/run_checkpoint.hpp"

#include <fmt/format.h>

#include "algorithm_run_io.hpp"
#include "checkpoint_lock.hpp"
#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/hdf5_writer.hpp"

namespace gpilqg {
namespace {

constexpr std::int64_t kFormatVersion = 1;
constexpr const char* kManifest = "manifest.h5";

std::vector<std::string> seed_texts(const std::vector<std::uint64_t>& seeds) {
  std::vector<std::string> out;
  for (const auto s : seeds) out.push_back(std::to_string(s));
  return out;
}

/// The run's identity as stored in the manifest: a resumed run must match it in every field.
struct Identity {
  std::string system, config, model_files;
  std::int64_t iterations = 0;
  std::vector<std::string> seeds, backends;
};

Identity identity_of(const RunConfig& config, const RunOptions& options) {
  return {config.system, config.text, config.files_text, config.iterations, seed_texts(options.seeds), options.backends};
}

std::string list_text(const std::vector<std::string>& values) {
  return values.empty() ? std::string("(none)") : fmt::format("{}", fmt::join(values, ","));
}

}  // namespace

std::filesystem::path RunCheckpoint::folder_for(const std::filesystem::path& result_file) {
  return std::filesystem::path(result_file.string() + ".checkpoint");
}

namespace {

/// True when `folder` holds no finished file: nothing, or only temporaries of interrupted writes and
/// the lock file (a checkpoint whose manifest was never written, e.g. after a failed or killed start).
bool holds_no_finished_file(const std::filesystem::path& folder) {
  std::error_code error;
  for (std::filesystem::directory_iterator it(folder, error), end; !error && it != end; it.increment(error))
    if (!is_atomic_temporary(it->path()) && it->path().filename() != CheckpointLock::kFileName) return false;
  return !error;
}

/// Removes what a failed or killed start left in `folder` (holds_no_finished_file), not the lock file.
void remove_unfinished_start(const std::filesystem::path& folder) {
  std::error_code error;
  for (std::filesystem::directory_iterator it(folder, error), end; !error && it != end; it.increment(error))
    if (it->path().filename() != CheckpointLock::kFileName) std::filesystem::remove_all(it->path(), error);
}

}  // namespace

RunCheckpoint RunCheckpoint::create(const std::filesystem::path& folder, const RunConfig& config, const RunOptions& options) {
  const auto in_the_way = [&] {
    return std::invalid_argument(fmt::format("{}: a checkpoint of an interrupted run is in the way; continue that run with "
                                             "--resume, or delete the folder to start over",
                                             folder.string()));
  };
  std::error_code error;
  if (std::filesystem::exists(folder, error) && !std::filesystem::is_directory(folder, error)) throw in_the_way();
  std::filesystem::create_directories(folder, error);
  if (error) throw std::runtime_error(fmt::format("{}: cannot create the checkpoint folder ({})", folder.string(), error.message()));
  // The lock before anything is looked at: a second run started at the same instant is refused here.
  std::shared_ptr<CheckpointLock> lock = CheckpointLock::take(folder);
  if (!holds_no_finished_file(folder)) throw in_the_way();
  remove_unfinished_start(folder);
  const Identity id = identity_of(config, options);
  // A checkpoint without its manifest could be neither resumed nor replaced: when the manifest
  // cannot be written, the folder goes too.
  struct RemoveUnlessKept {
    const std::filesystem::path& folder;
    bool keep = false;
    ~RemoveUnlessKept() {
      std::error_code ignored;
      if (!keep) std::filesystem::remove_all(folder, ignored);
    }
  } cleanup{folder};
  write_atomically(folder / kManifest, [&](const std::filesystem::path& temporary) {
    Hdf5Writer h5(temporary);
    h5.attribute("/", "format_version", kFormatVersion);
    h5.attribute("/", "system", id.system);
    h5.attribute("/", "config", id.config);
    h5.attribute("/", "model_files", id.model_files);
    h5.attribute("/", "iterations", id.iterations);
    h5.attribute("/", "seeds", id.seeds);
    h5.attribute("/", "backends", id.backends.empty() ? std::vector<std::string>{""} : id.backends);
    h5.close();
  });
  cleanup.keep = true;
  return RunCheckpoint(folder, std::move(lock));
}

RunCheckpoint RunCheckpoint::resume(const std::filesystem::path& folder, const RunConfig& config, const RunOptions& options,
                                    bool take_lock) {
  const std::filesystem::path manifest = folder / kManifest;
  if (!std::filesystem::exists(manifest))
    throw std::invalid_argument(fmt::format("{}: no checkpoint to resume from (expected {}); run without --resume to start",
                                         folder.string(), manifest.string()));
  std::shared_ptr<CheckpointLock> lock = take_lock ? CheckpointLock::take(folder) : nullptr;
  // What the manifest holds; a manifest that cannot be read (truncated, not HDF5, an attribute
  // missing or of another type) is a damaged checkpoint, reported as bad input with the way out.
  struct Stored {
    std::int64_t version = 0, iterations = 0;
    std::string system, config, model_files;
    std::vector<std::string> seeds, backends;
  } stored;
  try {
    const Hdf5Reader h5(manifest);
    stored.version = static_cast<std::int64_t>(h5.number_attribute("/", "format_version"));
    stored.system = h5.string_attribute("/", "system");
    stored.config = h5.string_attribute("/", "config");
    if (h5.has_attribute("/", "model_files")) stored.model_files = h5.string_attribute("/", "model_files");
    stored.iterations = static_cast<std::int64_t>(h5.number_attribute("/", "iterations"));
    stored.seeds = h5.string_list_attribute("/", "seeds");
    stored.backends = h5.string_list_attribute("/", "backends");
  } catch (const std::exception& e) {
    std::string reason = e.what();
    if (reason.rfind(manifest.string(), 0) == 0) reason.erase(0, reason.find_first_not_of(": ", manifest.string().size()));
    throw std::invalid_argument(fmt::format("{}: the checkpoint is damaged, its manifest cannot be read ({}); delete the "
                                            "folder {} to start the run over",
                                            manifest.string(), reason, folder.string()));
  }
  if (stored.version != kFormatVersion)
    throw std::runtime_error(fmt::format("{}: checkpoint format_version {}, this program reads {}", manifest.string(),
                                         stored.version, kFormatVersion));
  const Identity want = identity_of(config, options);
  if (stored.backends == std::vector<std::string>{""}) stored.backends.clear();
  const auto mismatch = [&](const std::string& field, const std::string& stored_value, const std::string& requested) {
    return std::invalid_argument(fmt::format("{}: the checkpoint was made with {} {}, this run asks for {}; resume with the "
                                          "same arguments, or delete the folder to start over",
                                          manifest.string(), field, stored_value, requested));
  };
  if (stored.system != want.system) throw mismatch("system", stored.system, want.system);
  if (stored.config != want.config) throw mismatch("a different config", "(stored in its 'config' attribute)", "this one");
  if (stored.model_files != want.model_files)
    throw mismatch("other texts of the files its config names", "(stored in its 'model_files' attribute)",
                   "the files as they read now: one was edited or replaced since");
  if (stored.iterations != want.iterations)
    throw mismatch("iterations", std::to_string(stored.iterations), std::to_string(want.iterations));
  if (stored.seeds != want.seeds) throw mismatch("seeds", list_text(stored.seeds), list_text(want.seeds));
  if (stored.backends != want.backends) throw mismatch("backends", list_text(stored.backends), list_text(want.backends));
  return RunCheckpoint(folder, std::move(lock));
}

std::filesystem::path RunCheckpoint::unit_file(const TaskContext& context, std::uint64_t seed, const std::string& name) const {
  return folder_ / fmt::format("seed-{}_task-{}_{}.h5", seed, context.task_index, name);
}

std::optional<AlgorithmRun> RunCheckpoint::restore(const TaskContext& context, std::uint64_t seed,
                                                   const std::string& name) const {
  const std::filesystem::path file = unit_file(context, seed, name);
  if (!std::filesystem::exists(file)) return std::nullopt;
  const SimulatorOf simulator_of = [&](const std::optional<LoopDiagnosis>& diagnosis) {
    return planning_simulator(loop_model(context.config), context.config.noise, context.models.simulator, diagnosis);
  };
  AlgorithmRun run = read_algorithm_run(file, context.config.system, simulator_of, context.config.gp.backend_settings);
  if (run.name != name)
    throw std::runtime_error(fmt::format("{}: holds algorithm '{}', expected '{}'", file.string(), run.name, name));
  if (static_cast<int>(run.iterations.size()) > context.config.iterations + 1)
    throw std::runtime_error(fmt::format("{}: holds {} iterations, the run has {}", file.string(), run.iterations.size(),
                                         context.config.iterations + 1));
  ++restored_;
  if (context.progress)
    context.progress(fmt::format("{} {}: resumed after iteration {}", context.task.name, name, run.iterations.size() - 1));
  return run;
}

void RunCheckpoint::save(const TaskContext& context, std::uint64_t seed, const AlgorithmRun& run) {
  write_atomically(unit_file(context, seed, run.name),
                   [&](const std::filesystem::path& temporary) { write_algorithm_run(temporary, run); });
  if (stop_requested_ && stop_requested_())
    throw RunInterrupted(fmt::format("stopped after {} iteration {} of {} (seed {}); progress is in {}", context.task.name,
                                     run.iterations.size() - 1, run.name, seed, folder_.string()));
}

void RunCheckpoint::remove() {
  std::error_code error;
  std::filesystem::remove_all(folder_, error);
  lock_.reset();
  if (error) throw std::runtime_error(fmt::format("{}: cannot delete the checkpoint folder ({})", folder_.string(), error.message()));
}

}  // namespace gpilqg
