// Rows of N float64 values from a binary (little-endian float64) or a text file,
// with the location of every value for error messages. Shared by the IMU and the
// odometer readers; callers validate what a column means.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/binary.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins {

/// Text layout: one record per line, values separated by blanks and/or commas;
/// '#' starts a comment (to the end of the line); blank lines are skipped.
class RowReader {
 public:
  /// `column_names` (ncols entries) name columns in messages. Throws InputError for a
  /// missing file, a directory, a truncated binary file and an unreadable text line.
  RowReader(const std::filesystem::path& file, FileLayout layout, int ncols,
            const char* const* column_names);
  ~RowReader();
  RowReader(const RowReader&) = delete;
  RowReader& operator=(const RowReader&) = delete;

  /// The next record's values, or nullptr at the end; valid until the next call.
  const double* next();
  /// 0-based index of the record last returned.
  std::uint64_t index() const { return index_; }
  const std::filesystem::path& file() const { return file_; }
  int ncols() const { return ncols_; }
  /// "'file': record 12 (0-based[, line 15]), column 3 (gyro_z)"; col < 0 leaves out the column.
  std::string where(int col) const;
  [[noreturn]] void fail(int col, const std::string& what) const;

 private:
  const double* next_text();
  std::filesystem::path file_;
  FileLayout layout_;
  int ncols_;
  const char* const* names_;
  std::unique_ptr<BinaryRowReader> bin_;
  std::ifstream text_;
  std::vector<char> text_buf_;
  std::string line_;
  std::uint64_t line_no_ = 0;
  std::vector<double> row_;
  std::uint64_t index_ = 0;
  std::uint64_t returned_ = 0;
};

}  // namespace wheelins
