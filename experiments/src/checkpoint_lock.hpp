#pragma once
/// @file checkpoint_lock.hpp
/// One run at a time on a checkpoint folder: `<folder>/lock`, an open-file-description lock
/// (fcntl F_OFD_SETLK, exclusive), held from the moment a run creates or resumes the folder until the
/// process ends or the folder is removed. Unlike a process's own fcntl lock it conflicts within one
/// process too (two runs of the Python package on one `out`). The holder writes its pid into the file,
/// so that a second run can name it. A second `run` on the same `--out`, or a `--resume` while the run
/// works, is refused at once instead of computing the same units and deleting the folder under it.

#include <filesystem>
#include <memory>

namespace gpilqg {

class CheckpointLock {
 public:
  /// Takes the lock of `folder` (which must exist). Throws std::invalid_argument "<folder>: in use by
  /// pid N (a run or --resume of the same result file is working in it); wait for it to end, or write
  /// to another file" when another holds it, std::runtime_error when the lock file cannot be opened.
  static std::shared_ptr<CheckpointLock> take(const std::filesystem::path& folder);
  ~CheckpointLock();
  CheckpointLock(const CheckpointLock&) = delete;
  CheckpointLock& operator=(const CheckpointLock&) = delete;

  /// The lock file's name inside the folder ("lock"): not a file of the checkpoint's content.
  static constexpr const char* kFileName = "lock";

 private:
  explicit CheckpointLock(int fd) : fd_(fd) {}
  int fd_;
};

}  // namespace gpilqg
