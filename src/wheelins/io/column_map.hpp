// How the columns of a text table (a vendor's CSV or text export of an IMU recording)
// become the samples `t [s], gyro xyz [rad/s], accel xyz [m/s^2]`: the delimiter, the
// lines before the header, each quantity's column (by header name or 0-based index), the
// units, a time counter's wrap and the sensor's physical range.
//
// A map is declared once and read three ways, all through one table of keys
// (docs/csv-import.md): a built-in preset (`xsens-dot`, `csv`), a small YAML file, or a
// compact string for the command line,
//   t=SampleTimeFine:us,gyro=Gyr_X,Gyr_Y,Gyr_Z:deg/s,accel=Acc_X,Acc_Y,Acc_Z:m/s^2
// and each of them may refine another (a preset with another gyro unit). Every map
// validates itself (validate()) and prints itself (describe(), and to_string(), which
// parses back to the same map). The table reader (io/table_reader.hpp) applies it.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "wheelins/io/diagnostics.hpp"

namespace wheelins {

/// What separates the fields of a line. kAuto: a `sep=X` line says it, else the first
/// header or data line: a comma if it has one, else a semicolon, else a tab, else blanks.
enum class Delimiter { kAuto, kComma, kSemicolon, kTab, kBlanks };
/// Whether the first line after the skipped ones names the columns. kAuto: it does when one
/// of its fields is not a number.
enum class HeaderMode { kAuto, kYes, kNo };
enum class TimeUnit { kSecond, kMillisecond, kMicrosecond, kNanosecond };
enum class GyroUnit { kRadPerSecond, kDegPerSecond };
enum class AccelUnit { kMeterPerSecond2, kStandardGravity };  ///< m/s^2, or g = 9.80665 m/s^2

/// Standard gravity: what a reading in g is multiplied by [m/s^2].
constexpr double kStandardGravity = 9.80665;

/// One column of the table: by header name (`name` non-empty) or by 0-based index.
struct ColumnRef {
  std::string name;
  int index = -1;
  bool empty() const { return name.empty() && index < 0; }
  /// The name, or the index as digits.
  std::string to_string() const;
  bool operator==(const ColumnRef&) const = default;
};

/// The largest 0-based column index a map may name (a table has fewer columns).
constexpr int kMaxColumnIndex = 9999;
/// The most lines skip_lines may skip before the header.
constexpr int kMaxSkipLines = 10000;

/// How a table's columns become samples. Units left unset (nullopt) come from the file:
/// its units line (`# units: s, deg/s, m/s^2`) or the unit in a column's header name
/// (`gyro_x[deg/s]`), else the defaults s, rad/s, m/s^2. A default-constructed map is the
/// `csv` preset: `t, gx, gy, gz, ax, ay, az` by index.
struct ColumnMap {
  std::string preset = "csv";  ///< the preset it started from ("" if none), for messages
  Delimiter delimiter = Delimiter::kAuto;
  int skip_lines = -1;          ///< lines skipped before the header; -1: a first `sep=` line
  HeaderMode header = HeaderMode::kAuto;
  ColumnRef time{"", 0};
  std::array<ColumnRef, 3> gyro{ColumnRef{"", 1}, ColumnRef{"", 2}, ColumnRef{"", 3}};
  std::array<ColumnRef, 3> accel{ColumnRef{"", 4}, ColumnRef{"", 5}, ColumnRef{"", 6}};
  std::optional<TimeUnit> time_unit;
  std::optional<GyroUnit> gyro_unit;
  std::optional<AccelUnit> accel_unit;
  /// A time counter's wrap in ticks of the time unit (2^32 for a 32-bit microsecond
  /// counter); 0: the time does not wrap. Wrapped counters are unwrapped.
  std::uint64_t time_wrap = 0;
  /// Multiplies the time after the unit (a clock of 32768 ticks/s: unit s, scale 1/32768).
  double time_scale = 1.0;
  /// The sensor's full scale [deg/s], 0: not stated. A reading beyond it + 5 % is a fault.
  double gyro_range_dps = 0.0;
  /// The sensor's full scale [m/s^2], 0: not stated.
  double accel_range_m_s2 = 0.0;

  /// Throws InputError (starting "column map: ") naming the first key that is wrong:
  /// a quantity without a column, one column for two quantities, column names without a
  /// header, a value outside its range.
  void validate() const;
  /// A few readable lines: every setting and where the unset ones come from.
  std::string describe() const;
  /// The compact command-line form (every key), which parse_column_map() reads back to this
  /// map (when no column name holds ',' or ':', which that form cannot carry).
  std::string to_string() const;

  /// The time's factor to seconds for the unit (unset: s), times time_scale.
  double seconds_per_tick() const;
  /// The gyro's factor to rad/s (unset: rad/s), the accel's to m/s^2 (unset: m/s^2).
  double gyro_factor() const;
  double accel_factor() const;
  /// The limits beyond which a reading is a fault: the stated range + 5 %, else 20000 deg/s
  /// and 2000 m/s^2 (no sensor reads more) [rad/s], [m/s^2].
  double gyro_limit() const;
  double accel_limit() const;

  bool operator==(const ColumnMap&) const = default;
};

/// The readings beyond the stated range that are still taken (saturation may overshoot).
constexpr double kRangeMargin = 1.05;
/// Limits without a stated range: no MEMS sensor reads more.
constexpr double kDefaultGyroLimitDps = 20000.0;
constexpr double kDefaultAccelLimit = 2000.0;

/// The built-in presets: "xsens-dot" (an Xsens DOT CSV export as the app writes it) and
/// "csv" (a plain `t, gx, gy, gz, ax, ay, az` table). Throws InputError naming the known
/// presets (and the closest) for another name.
ColumnMap column_map_preset(std::string_view name);
/// The preset names, for messages and --help.
std::vector<std::string> column_map_preset_names();

/// Reads a YAML column map (docs/csv-import.md) over `base`: a `preset` key starts from
/// that preset instead; every other key refines. Unknown keys are warned about (with the
/// closest known key) through `warn`; errors are InputErrors naming the file, key and line.
ColumnMap load_column_map(const std::filesystem::path& file, const ColumnMap& base = ColumnMap{},
                          const WarningSink& warn = {});
/// Reads the command-line form over `base`: `key=value` items separated by commas; a
/// column list continues over commas (`gyro=Gyr_X,Gyr_Y,Gyr_Z`), and a column key may end
/// with `:UNIT` (`t=SampleTimeFine:us`). Unknown keys are errors here (typed by hand).
ColumnMap parse_column_map(std::string_view text, const ColumnMap& base = ColumnMap{});
/// True if `arg` names a map file rather than being a map string: it ends in .yaml or .yml,
/// or names an existing file.
bool is_column_map_file(std::string_view arg);
/// What `wheelins import --preset NAME --columns MAP.yaml|STRING` means: the preset (empty:
/// `csv`, or the map's own `preset` key), refined by the map (empty: none). A map naming
/// another preset than `preset` is an error. The result is validated.
ColumnMap column_map_from_options(std::string_view preset, std::string_view columns,
                                  const WarningSink& warn = {});

/// Unit spellings: "s", "ms", "us" (also "µs"), "ns"; "rad/s", "deg/s" (also "dps");
/// "m/s^2" (also "m/s2", "m/s²"), "g". nullopt for anything else.
std::optional<TimeUnit> parse_time_unit(std::string_view text);
std::optional<GyroUnit> parse_gyro_unit(std::string_view text);
std::optional<AccelUnit> parse_accel_unit(std::string_view text);
const char* to_string(TimeUnit u);
const char* to_string(GyroUnit u);
const char* to_string(AccelUnit u);
const char* to_string(Delimiter d);
const char* to_string(HeaderMode h);

}  // namespace wheelins
