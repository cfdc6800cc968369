// Odometer files (the Wheel-INS `odo.bin`): 2 columns `t [s], forward speed [m/s]`,
// binary little-endian float64 rows or text (blank/comma separated, '#' comments).
// Validation as for IMU files: finite values, strictly increasing time, not empty;
// errors name the file, the 0-based record (and the line for text) and the column.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>

#include "wheelins/io/manifest.hpp"

namespace wheelins {

class RowReader;
class BinaryRowWriter;
class AtomicTextFile;

struct OdoSample {
  double t = 0.0;      ///< [s] (file time + time_offset)
  double speed = 0.0;  ///< forward speed [m/s]; negative when reversing
};

extern const char* const kOdoColumnNames[2];

/// Streams an odometer file; the constructor reads the first record (empty file: error).
class OdoReader {
 public:
  explicit OdoReader(const std::filesystem::path& file, FileLayout layout = FileLayout::kBinary,
                     double time_offset = 0.0);
  ~OdoReader();
  OdoReader(const OdoReader&) = delete;
  OdoReader& operator=(const OdoReader&) = delete;

  bool next(OdoSample& out);
  std::uint64_t index() const { return index_; }  ///< 0-based index of the last record returned
  double first_time() const { return first_.t; }
  const std::filesystem::path& file() const { return file_; }

 private:
  bool read(OdoSample& s);
  std::filesystem::path file_;
  double offset_;
  std::unique_ptr<RowReader> rows_;
  OdoSample first_;
  bool has_first_ = true, started_ = false;
  double prev_t_ = 0.0;
  std::uint64_t index_ = 0;
};

/// Writes an odometer file through `file.partial` (commit() moves it into place).
/// Refuses an existing file unless `overwrite`.
class OdoWriter {
 public:
  explicit OdoWriter(const std::filesystem::path& file, FileLayout layout = FileLayout::kBinary,
                     bool overwrite = false);
  ~OdoWriter();
  OdoWriter(const OdoWriter&) = delete;
  OdoWriter& operator=(const OdoWriter&) = delete;

  void write(const OdoSample& s);
  void commit();
  std::uint64_t rows() const { return rows_; }

 private:
  std::filesystem::path file_;
  std::unique_ptr<BinaryRowWriter> bin_;
  std::unique_ptr<AtomicTextFile> text_;
  std::uint64_t rows_ = 0;
  double last_t_ = 0.0;
};

}  // namespace wheelins
