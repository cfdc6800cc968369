// Little-endian float64 row files (the Wheel-INS dataset layout): block-buffered
// streaming in both directions, constant memory whatever the file size.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/atomic_file.hpp"

namespace wheelins {

/// Reads rows of `ncols` float64 values. Rejects (with InputError naming the file
/// and the record) a missing/unreadable file, a directory, and a size that is not a
/// multiple of the row size. Values are returned as stored (no NaN checks here:
/// callers validate what a column means).
class BinaryRowReader {
 public:
  BinaryRowReader(const std::filesystem::path& file, int ncols);
  ~BinaryRowReader();
  BinaryRowReader(const BinaryRowReader&) = delete;
  BinaryRowReader& operator=(const BinaryRowReader&) = delete;

  /// Pointer to the next row's ncols values, or nullptr at the end. Valid until the next call.
  const double* next();
  std::uint64_t rows() const { return rows_; }          ///< rows in the file
  std::uint64_t index() const { return next_row_ - 1; }  ///< 0-based index of the last row returned
  const std::filesystem::path& file() const { return file_; }
  int ncols() const { return ncols_; }

 private:
  std::filesystem::path file_;
  int ncols_;
  std::FILE* fp_ = nullptr;
  std::uint64_t rows_ = 0;
  std::uint64_t next_row_ = 0;
  std::vector<double> block_;
  std::size_t block_rows_ = 0, block_pos_ = 0;
};

/// Writes rows of `ncols` float64 values to `file` through an AtomicFile; commit() moves it
/// into place. Without commit() (an error part-way) the partial file is removed and nothing
/// the user had is touched.
class BinaryRowWriter {
 public:
  BinaryRowWriter(const std::filesystem::path& file, int ncols);

  void write(const double* row);
  void commit();
  std::uint64_t rows() const { return rows_; }

 private:
  void flush();
  AtomicFile out_;
  int ncols_;
  std::vector<double> block_;
  std::uint64_t rows_ = 0;
};

}  // namespace wheelins
