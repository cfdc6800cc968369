// A directory of outputs (a run's trajectories, a simulated dataset, an experiment's
// tables) that appears complete or not at all.
//
// Everything is written into a private staging directory beside the target
// (`.NAME.partial-PID-XXXXXX`, same file system); commit() renames it onto the target in
// one step (rename(2) onto an absent or empty directory; an atomic exchange with an
// earlier output when replacing one). A killed writer leaves only its staging directory,
// which the next writer to the same target removes; a reader never sees a mixed set.
//
// The target must be absent, empty, or an earlier output of the same kind (marked by the
// file `.wheelins`, which lists the files wheelins wrote there), and an earlier output is
// replaced only with `overwrite`. Replacing replaces only what wheelins wrote: anything the
// user added since (notes, a run's results inside a dataset) is moved into the new output
// and named (`notice`); a file the new output would write under the same name is refused.
// A directory holding anything else (the user's files, a dataset when results are written,
// an input of the command) is refused, with or without `overwrite`. A symbolic link is
// followed: the output goes into the directory it points to and the link stays. While the
// work runs the target is locked (flock): a second writer fails at once with a clear error
// instead of writing over the first one's files.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/file_lock.hpp"

namespace wheelins {

struct OutputDirOptions {
  bool overwrite = false;
  /// What is written: "results", "dataset", "experiment" (the marker's content, messages).
  std::string kind = "results";
  /// The option that allows replacing an earlier output, for messages ("--force").
  std::string overwrite_hint = "--force";
  /// Files the command reads: a target that holds one of them is never replaced.
  std::vector<std::filesystem::path> inputs;
  /// Told which entries of an earlier output were kept because wheelins did not write them.
  std::function<void(const std::string&)> notice;
};

/// The marker file of a directory written through OutputDir.
inline constexpr const char* kOutputMarker = ".wheelins";

class OutputDir {
 public:
  /// Checks the target, locks it and creates the staging directory (so an unwritable
  /// place fails here, before any work). Throws InputError naming the directory.
  OutputDir(const std::filesystem::path& target, const OutputDirOptions& options);
  /// Removes the staging directory unless committed (and the target if this made it empty).
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  /// Where to write; its files appear under target() at commit().
  const std::filesystem::path& staging() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }
  /// The path a file `relative` will have after commit().
  std::filesystem::path final_path(const std::filesystem::path& relative) const { return target_ / relative; }
  /// Writes the marker and moves the staging directory into place.
  void commit();
  bool committed() const { return committed_; }
  /// The entries of the earlier output that commit() kept (not written by wheelins).
  const std::vector<std::string>& kept() const { return kept_; }

 private:
  void cleanup() noexcept;
  /// Moves the staging directory onto the earlier output (an atomic exchange where the file
  /// system has one) and removes the earlier output.
  void replace_target(const std::string& quoted);
  std::filesystem::path target_, staging_;
  OutputDirOptions opt_;
  std::optional<FileLock> lock_;
  bool created_target_ = false;
  bool replace_ = false;
  bool committed_ = false;
  std::vector<std::string> kept_;
};

/// "what kind of output `dir` holds": "" if absent or empty, the marker's kind, or
/// "foreign" for a directory with other files ("not a directory" for a file).
std::string output_dir_kind(const std::filesystem::path& dir);

}  // namespace wheelins
