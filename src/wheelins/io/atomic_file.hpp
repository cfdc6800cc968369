// Output files that appear complete or not at all: written under a temporary
// name (`file.partial-PID-N`) and moved into place by commit(). An existing file is
// replaced only when the caller asked for it (`overwrite`). Every file wheelins writes
// whole goes through AtomicFile (text, binary rows, manifests, study results); a rendered
// image through move_into_place().
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace wheelins {

/// Throws InputError if `file` is a directory, or exists and `overwrite` is false.
void check_output_target(const std::filesystem::path& file, bool overwrite);

/// True if `a` and `b` are the same file: the same inode when both exist (also through a
/// link or another spelling), else the same path once `.`, `..` and links are resolved.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

/// A file of a command and what names it in messages: an output's option ("--json"), an
/// input's role ("the truth (--truth)").
struct NamedFile {
  std::filesystem::path file;
  std::string name;
};
using OutputFile = NamedFile;
/// `files`, each named `name`.
std::vector<NamedFile> named_files(const std::vector<std::filesystem::path>& files, const std::string& name);

/// The rule for every command's output files, checked before anything is written so that a
/// refusal leaves nothing behind (all or nothing): each is given (an empty name is an error
/// naming its option), is not a directory, is none of `inputs` (refused with or without
/// `overwrite`: an output never replaces what the command reads), is not the same file as
/// another output, and replaces an existing file only with `overwrite`. Messages name the
/// option.
void check_output_files(const std::vector<OutputFile>& outputs, const std::vector<NamedFile>& inputs,
                        bool overwrite);

/// Appends `value` to `out`: the shortest text that reads back to the same double
/// when `significant` is 0, otherwise that many significant digits. NaN -> "nan".
void append_double(std::string& out, double value, int significant = 0);
/// The same into `dst`, which must have room for kMaxDoubleChars; returns the end.
constexpr int kMaxDoubleChars = 32;
char* write_double(char* dst, double value, int significant = 0);
/// Appends `value` with a fixed number of decimals (e.g. degrees in KML).
void append_fixed(std::string& out, double value, int decimals);

/// Writes the bytes of one chunk to `fd` (a temporary file); throws on failure. Tests put a
/// failing one in to see that nothing half-written is left.
using ChunkWriter = std::function<void(int fd, std::string_view chunk)>;

/// How an AtomicFile replaces and where it writes meanwhile.
struct AtomicFileOptions {
  /// false: an existing `file` is refused (check_output_target), when the writer opens and
  /// again when it commits; true: the finished file replaces it.
  bool overwrite = true;
  /// The temporary name; empty: unique_partial(file) (`file.partial-PID-N`, which
  /// sweep_stale_partials() clears after a killed writer).
  std::filesystem::path temporary;
};

/// The one writer of a file that appears complete or not at all: the bytes go to a
/// temporary beside it (created exclusively: two writers never share one), commit() renames
/// it over `file` (readers see the old file or the new one, never a part); destroyed without
/// commit() (an exception part-way), the temporary is removed. The parent directory is
/// created. There is no fsync: a machine that crashes may lose its latest files (readers
/// reject a file cut short); a failing process or a full disk leaves nothing behind.
class AtomicFile {
 public:
  AtomicFile(const std::filesystem::path& file, const AtomicFileOptions& options);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Writes all of `bytes` (unbuffered: callers write in large blocks); throws InputError.
  void write(const void* data, std::size_t bytes);
  void write(std::string_view text) { write(text.data(), text.size()); }
  /// The temporary's descriptor (for a ChunkWriter).
  int fd() const { return fd_; }
  void commit();
  bool committed() const { return committed_; }
  const std::filesystem::path& file() const { return file_; }
  const std::filesystem::path& temporary() const { return tmp_; }

 private:
  std::filesystem::path file_, tmp_;
  bool overwrite_;
  int fd_ = -1;
  bool committed_ = false;
};

/// Moves the finished `temporary` over `file` by a rename; without `overwrite` an existing
/// `file` is refused. On failure the temporary is removed and InputError names `file`.
void move_into_place(const std::filesystem::path& temporary, const std::filesystem::path& file,
                     bool overwrite);

/// `text` written to `file` through an AtomicFile, in chunks of 64 KiB; `write_chunk`
/// (tests) replaces the writing of each chunk.
void write_file_atomic(const std::filesystem::path& file, std::string_view text,
                       const AtomicFileOptions& options = {}, const ChunkWriter& write_chunk = {});

/// A buffered text file written through an AtomicFile; commit() renames it into place.
class AtomicTextFile {
 public:
  AtomicTextFile(const std::filesystem::path& file, bool overwrite);

  /// Appends text; flushed to disk in large blocks.
  void write(std::string_view text);
  /// The internal buffer, for callers that format in place; call maybe_flush() after.
  std::string& buffer() { return buf_; }
  void maybe_flush();
  void commit();
  bool committed() const { return out_.committed(); }
  const std::filesystem::path& file() const { return out_.file(); }

 private:
  void flush();
  AtomicFile out_;
  std::string buf_;
};

}  // namespace wheelins
