// Files that several processes (on several machines, over a shared directory) write at
// once: every result appears complete or not at all, and one process at a time makes a
// dataset.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "wheelins/io/atomic_file.hpp"

namespace wheelins::study {

/// How a study writes a file others may read or write at once (a result, a report, a
/// dataset's settings): through an AtomicFile whose temporary has a name unique over the
/// machines sharing the directory (`.NAME.tmp-HOST-PID-N`, hidden), replacing the old file.
/// With io's write_file_atomic(file, text, shared_file(file)): a process killed or failing
/// part-way leaves no `file`, or the old one. There is no fsync (it cost 8 ms a result here,
/// more than the rest of a job's overhead): a machine that crashes may lose its latest
/// results or leave one cut short, and the readers reject a result without its final line.
AtomicFileOptions shared_file(const std::filesystem::path& file);

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

}  // namespace wheelins::study
