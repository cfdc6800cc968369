// Files that several processes (on several machines, over a shared directory) write at
// once: every result appears complete or not at all, and one process at a time makes a
// dataset.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace wheelins::study {

/// Writes the bytes of one chunk to `fd` (the temporary file); throws on failure.
using ChunkWriter = std::function<void(int fd, std::string_view chunk)>;

/// Writes `text` to `file` through a temporary file of a unique name in the same directory
/// (`.NAME.tmp-HOST-PID-N`) renamed over `file`: a process killed or failing part-way leaves
/// no `file`, or the old one. The temporary file is removed on failure. `write_chunk` (tests)
/// replaces the write of each 64 KiB chunk. There is no fsync (it cost 8 ms a result here, more
/// than the rest of a job's overhead): a machine that crashes may lose its latest results or
/// leave one cut short, and the readers reject a result without its final line.
void write_file_atomic(const std::filesystem::path& file, std::string_view text,
                       const ChunkWriter& write_chunk = {});

/// The whole file; nullopt-like empty string and false when it cannot be read.
bool read_file(const std::filesystem::path& file, std::string& out);

/// The files a study report wrote into its results directory, listed in `.wheelins-report`
/// there (one relative path a line). A report replaces only those: a file of the same name
/// that it did not write (the user's own report.md or plots/a.gp) is refused, with or
/// without --force. A directory reported into before the list existed: a file counts as the
/// report's when its first line is the one the report writes there.
class ReportFiles {
 public:
  explicit ReportFiles(const std::filesystem::path& dir);
  /// Throws InputError if `dir/rel` exists and is not the report's. `first_line`: what the
  /// report writes on its first line (for a directory without the list; "" matches nothing).
  void check(const std::filesystem::path& rel, const std::string& first_line) const;
  /// Records `rel` as written and saves the list (atomically).
  void add(const std::vector<std::filesystem::path>& rels);

 private:
  std::filesystem::path dir_;
  bool listed_ = false;
  std::vector<std::string> names_;
};

/// This machine's name ("host" if it has none).
std::string host_name();

/// A unique suffix for temporary names: host, process id and a counter.
std::string unique_suffix();

/// An exclusive advisory lock (flock) on `file` (created if missing), held until
/// destruction; waits for other holders. Where the file system has no locks (some network
/// file systems) locked() is false and the caller relies on atomic renames alone.
class FileLock {
 public:
  explicit FileLock(const std::filesystem::path& file);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  bool locked() const { return locked_; }

 private:
  int fd_ = -1;
  bool locked_ = false;
};

}  // namespace wheelins::study
