// The one advisory lock of wheelins' writers: an output directory while a command fills
// it, a study's dataset while one process generates it.
#pragma once

#include <filesystem>

namespace wheelins {

/// An exclusive advisory lock (flock) on a file or a directory, held until destruction (or
/// release()). A directory is opened as it is; a missing file is created (a lock file).
/// Opening it fails with InputError naming the path; taking the lock does not throw: the
/// caller decides what a lock held elsewhere, or a file system without locks (some network
/// file systems: the writers then rely on atomic renames alone), means.
class FileLock {
 public:
  enum class Wait { kUntilFree, kNo };
  enum class State { kLocked, kHeldElsewhere, kNoLocks };

  FileLock(const std::filesystem::path& path, Wait wait);
  ~FileLock() { release(); }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

  State state() const { return state_; }
  bool locked() const { return state_ == State::kLocked; }
  /// errno of the failed flock (kNoLocks), else 0.
  int error() const { return error_; }
  /// Closes the descriptor, which lets the lock go.
  void release() noexcept;

 private:
  int fd_ = -1;
  State state_ = State::kNoLocks;
  int error_ = 0;
};

}  // namespace wheelins
