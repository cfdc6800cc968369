// Importing vendor CSV / text exports of IMU recordings (docs/csv-import.md): each table,
// read through its column map (io/table_reader.hpp), becomes
//
//   OUT/<module>_imu.bin   7 little-endian float64 columns: t [s], gyro x y z [rad/s],
//                          accel x y z [m/s^2] (the layout of docs/manifest.md)
//
// with the rows that cannot be samples left out and counted. Every file is written under
// a temporary name and all appear together at the end: on an error (a table with too
// many bad rows, a write error, an exception from the progress callback such as an
// interrupt) nothing is left in OUT; the temporaries of an import that was killed are
// removed by the next import into the same directory. Inputs are never overwritten, and
// an existing output only with `overwrite` (then only the files this import writes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "wheelins/io/column_map.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/table_reader.hpp"

namespace wheelins {

/// One table to import: its module name (the output is `<module>_imu.bin`), the file and
/// how to read it.
struct TableInput {
  std::string module;
  std::filesystem::path file;
  ColumnMap map;
};

struct TableImportOptions {
  bool overwrite = false;  ///< replace existing `<module>_imu.bin` files (never an input)
  /// The largest fraction of a table's data rows that may be left out (TableReadOptions).
  double max_bad_fraction = 0.01;
  WarningSink warn;  ///< unit overrides; may be empty
  /// Called every few thousand rows and at the end with (lines read, lines in all the
  /// tables; 0 if unknown). It may throw (e.g. on an interrupt): nothing is left behind.
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

/// What one table gave.
struct ImportedTable {
  std::string module;
  std::filesystem::path source;  ///< the table
  std::filesystem::path output;  ///< OUT/<module>_imu.bin
  std::uint64_t rows_read = 0;   ///< data rows
  std::uint64_t rows_kept = 0;   ///< samples written
  RowFaults faults;              ///< the rows left out, per class, with the first of each
  TableTiming timing;            ///< first/last time, rate, jitter, gaps
  ColumnMap map;                 ///< the map as applied (units resolved)
  std::vector<std::string> notes;  ///< where units and the delimiter came from
};

/// Imports every table into `out_dir` (created if missing), in the order given. Throws
/// InputError for a bad module name (check_module_name), two inputs with one module name,
/// an output that exists (without `overwrite`) or that is one of the inputs, and any
/// table the reader rejects; then nothing is written.
std::vector<ImportedTable> import_tables(const std::vector<TableInput>& inputs,
                                         const std::filesystem::path& out_dir,
                                         const TableImportOptions& options = {});

/// Throws InputError unless `name` is a usable module name: not empty, at most 200
/// characters of [A-Za-z0-9_.-], not starting with '.' and without "..", so that
/// `<name>_imu.bin` is a plain file name in the output directory.
void check_module_name(const std::string& name);
/// The module name a table's file name gives: its name without the extension, other
/// characters than [A-Za-z0-9_.-] as '_' (`IMU1_radial.csv` -> `IMU1_radial`,
/// `left wheel.csv` -> `left_wheel`); "imu" if nothing is left.
std::string module_name_from_file(const std::filesystem::path& file);

/// A short table, one line per file: file, module, rows, kept, rate, jitter, span, gaps
/// and the rows left out by class (with the first row of each), for `wheelins import`.
std::string table_import_report(const std::vector<ImportedTable>& tables);

}  // namespace wheelins
