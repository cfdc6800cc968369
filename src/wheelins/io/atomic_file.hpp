// Output files that appear complete or not at all: written under a temporary
// name (`file.partial`) and moved into place by commit(). An existing file is
// replaced only when the caller asked for it (`overwrite`).
#pragma once

#include <cstdio>
#include <filesystem>
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

/// A buffered text file written through `file.partial`; commit() renames it into
/// place. Without commit() (an exception part-way) the partial file is removed.
class AtomicTextFile {
 public:
  AtomicTextFile(const std::filesystem::path& file, bool overwrite);
  ~AtomicTextFile();
  AtomicTextFile(const AtomicTextFile&) = delete;
  AtomicTextFile& operator=(const AtomicTextFile&) = delete;

  /// Appends text; flushed to disk in large blocks.
  void write(std::string_view text);
  /// The internal buffer, for callers that format in place; call maybe_flush() after.
  std::string& buffer() { return buf_; }
  void maybe_flush();
  void commit();
  bool committed() const { return committed_; }
  const std::filesystem::path& file() const { return file_; }

 private:
  void flush();
  std::filesystem::path file_, tmp_;
  bool overwrite_;
  std::FILE* fp_ = nullptr;
  std::string buf_;
  bool committed_ = false;
};

}  // namespace wheelins
