// Streams a text table (a vendor's CSV or text export of one IMU) through a column map
// (io/column_map.hpp) and yields its samples `t [s], gyro [rad/s], accel [m/s^2]`, in
// constant memory.
//
// Rows that cannot be samples are left out and counted per class (RowFault): too few
// fields, a value that is not a number, NaN or infinite, all six sensor values exactly 0
// (what a sensor writes before its first sample), a reading beyond the sensor's range
// + 5 %, and a time that does not increase. Times are kept as they are (no resampling:
// jitter and gaps stay); the reader measures them (TableTiming). At the end of the file
// the bad rows are held against a limit (TableReadOptions::max_bad_fraction): more is an
// InputError naming the file, the count of each class and its first row. docs/csv-import.md.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/column_map.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/imu_file.hpp"

namespace wheelins {

/// Why a row is not a sample, in the order the checks run (a row counts once, in the
/// first class that applies).
enum class RowFault : int {
  kColumns = 0,        ///< fewer fields than the map needs (extra fields are fine)
  kUnparsable,         ///< a value that is empty or not a number (or a counter outside its wrap)
  kNonFinite,          ///< NaN or infinite (`NaN`, `Infinity`, `-inf`, ...)
  kAllZero,            ///< the six sensor values all exactly 0
  kBeyondRange,        ///< a reading beyond the sensor's range + 5 % (e.g. 1e30)
  kTimeNotIncreasing,  ///< the time repeats or goes back from the last kept row's
};
constexpr std::size_t kRowFaultClasses = 6;
/// All classes, in check order.
constexpr std::array<RowFault, kRowFaultClasses> kRowFaults = {
    RowFault::kColumns,  RowFault::kUnparsable,  RowFault::kNonFinite,
    RowFault::kAllZero,  RowFault::kBeyondRange, RowFault::kTimeNotIncreasing};
/// "wrong column count", "unparsable value", "NaN or infinite", "all zero", "beyond range",
/// "time not increasing".
const char* to_string(RowFault f);
/// A short name for tables: "columns", "unparsable", "non-finite", "zero", "range", "time".
const char* short_name(RowFault f);

/// A row that was left out: where it is and why.
struct RowFaultExample {
  std::uint64_t row = 0;   ///< 0-based data row (the header and comment lines not counted)
  std::uint64_t line = 0;  ///< 1-based line of the file
  std::string what;        ///< e.g. "column 8 (Gyr_X) is NaN"
};

/// The rows left out of a table, per class, with the first of each.
struct RowFaults {
  std::array<std::uint64_t, kRowFaultClasses> count{};
  std::array<RowFaultExample, kRowFaultClasses> first{};  ///< meaningful where count > 0
  std::uint64_t operator[](RowFault f) const { return count[static_cast<std::size_t>(f)]; }
  const RowFaultExample& first_of(RowFault f) const { return first[static_cast<std::size_t>(f)]; }
  std::uint64_t total() const;
  /// "1 all zero (row 0), 1 NaN or infinite (row 8)"; "none" without faults. With
  /// `details`, each class's first row also gives its line and what was wrong.
  std::string summary(bool details = false) const;
};

/// A time gap: the interval before data row `row` is longer than 5 median intervals.
struct TableGap {
  std::uint64_t row = 0;   ///< 0-based data row after the gap
  std::uint64_t line = 0;  ///< its 1-based line
  double t_before = 0.0, t_after = 0.0;  ///< [s]
  double length() const { return t_after - t_before; }
};

/// The times of the kept rows as they are: span, median interval (the rate), its spread,
/// and the gaps. Intervals of files with more than 4097 kept rows are binned (bins of
/// 1/2048 of the first 4096 intervals' median, each bin's mean taken), so the quantiles are
/// exact for a regular clock and within 0.05 % of that median otherwise.
struct TableTiming {
  double t_first = 0.0, t_last = 0.0;  ///< [s]
  std::uint64_t intervals = 0;
  double interval_median = 0.0;                    ///< [s]
  double interval_p05 = 0.0, interval_p95 = 0.0;   ///< 5th and 95th percentiles [s]
  double interval_min = 0.0, interval_max = 0.0;   ///< [s]
  /// Intervals longer than kGapFactor median intervals (in a file with more than 4097 kept
  /// rows: than kGapFactor times the median of its first 4096 intervals).
  std::uint64_t gap_count = 0;
  double longest_gap = 0.0;  ///< [s], 0 if none
  static constexpr std::size_t kMaxStoredGaps = 1000;
  std::vector<TableGap> gaps;  ///< the first kMaxStoredGaps gaps
  static constexpr double kGapFactor = 5.0;

  double span() const { return t_last - t_first; }
  /// 1 / interval_median [Hz]; 0 without intervals.
  double rate_hz() const { return interval_median > 0.0 ? 1.0 / interval_median : 0.0; }
  /// (p95 - p05) / 2: half the spread of the middle 90 % of the intervals [s].
  double jitter() const { return 0.5 * (interval_p95 - interval_p05); }
};

struct TableReadOptions {
  /// The largest fraction of data rows that may be left out; more is an InputError at the
  /// end of the file. In [0, 1]; 1 accepts any number (the file still needs 2 valid rows).
  double max_bad_fraction = 0.01;
  /// Told when the map's unit overrides a different unit the file states; may be empty.
  WarningSink warn;
};

/// What a table held: rows read and kept, the faults, the timing, and the map as applied
/// (its units resolved from the file where the map left them open).
struct TableSummary {
  std::uint64_t rows_read = 0;  ///< data rows (the header, blank and comment lines not counted)
  std::uint64_t rows_kept = 0;
  RowFaults faults;
  TableTiming timing;
  ColumnMap map;                 ///< every unit set
  std::vector<std::string> notes;  ///< where units and the delimiter came from
};

/// Streams one table. The constructor reads up to the first data row: the `sep=` and
/// skipped lines, the header (its names resolved to indices: an unknown name is an
/// InputError listing the header's columns and the closest name), comment lines and a units
/// line, so that every setting is known before the first row.
class TableReader {
 public:
  TableReader(const std::filesystem::path& file, const ColumnMap& map, const TableReadOptions& options = {});
  ~TableReader();
  TableReader(const TableReader&) = delete;
  TableReader& operator=(const TableReader&) = delete;

  /// The next valid sample (t [s], gyro [rad/s], accel [m/s^2]); false at the end. At the
  /// end it checks the limits: too many bad rows, or fewer than 2 valid ones, throw InputError.
  bool next(ImuRow& out);

  /// Complete once next() has returned false; before that, counts so far.
  const TableSummary& summary() const { return summary_; }
  /// Lines of the file read so far (for progress).
  std::uint64_t lines_read() const;
  const std::filesystem::path& file() const { return file_; }

 private:
  struct Impl;
  std::filesystem::path file_;
  TableSummary summary_;
  std::unique_ptr<Impl> impl_;
};

/// The number of lines of a text file (newlines, plus one for a last line without one):
/// a quick pass for a progress total. 0 if it cannot be read.
std::uint64_t count_text_lines(const std::filesystem::path& file);

}  // namespace wheelins
