// Vendor tables (CSV / text exports) as IMU files: column maps (presets, YAML, the
// command-line string), the table reader's fault classes, units and timing, and the
// import into `<module>_imu.bin` with its all-or-nothing writing. Fixtures are small
// synthetic tables written by the tests; the real Xsens DOT exports of the shared data
// are read when they are there (skipped otherwise).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <sstream>

#include "io_test_util.hpp"
#include "wheelins/io/column_map.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/table_import.hpp"
#include "wheelins/io/table_reader.hpp"

using namespace wheelins;
using namespace wheelins::iotest;
namespace fs = std::filesystem;

namespace {

struct ReadAll {
  std::vector<ImuRow> rows;
  TableSummary summary;
};

ReadAll read_all(const fs::path& file, const ColumnMap& map, double max_bad = 1.0, const WarningSink& warn = {}) {
  TableReadOptions o;
  o.max_bad_fraction = max_bad;
  o.warn = warn;
  TableReader r(file, map, o);
  ReadAll out;
  ImuRow row;
  while (r.next(row)) out.rows.push_back(row);
  out.summary = r.summary();
  return out;
}

constexpr const char* kDotHeader =
    "PacketCounter,SampleTimeFine,Euler_X,Euler_Y,Euler_Z,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z,Mag_X,Mag_Y,Mag_Z,"
    "Status,";

/// One DOT row as the app writes it: `, ` between the fields and at the end.
std::string dot_row(int counter, std::uint64_t time_us, const std::string& acc, const std::string& gyr) {
  return std::to_string(counter) + ", " + std::to_string(time_us) + ", -84.04, -40.15, 3.64, " + acc + ", " + gyr +
         ", 0.1166, 0.4038, 1.2617, 0, \n";
}

std::string values(double x, double y, double z) {
  std::ostringstream s;
  s.precision(17);
  s << x << ", " << y << ", " << z;
  return s.str();
}

/// A DOT export of `n` rows at 8333 us from `t0_us`, with the gyro and accel of row k
/// below (distinct per row).
Vec3 dot_gyro(int k) { return Vec3(10.0 + 0.01 * k, -20.5, 0.25 * k); }
Vec3 dot_accel(int k) { return Vec3(0.5, -9.81 + 0.001 * k, 1.5); }

std::string dot_text(int n, std::uint64_t t0_us, const std::map<int, std::string>& replace = {}) {
  std::string s = "sep=,\n" + std::string(kDotHeader) + "\n";
  for (int k = 0; k < n; ++k) {
    if (auto it = replace.find(k); it != replace.end()) {
      s += it->second;
      continue;
    }
    const Vec3 g = dot_gyro(k), a = dot_accel(k);
    s += dot_row(k, (t0_us + 8333ull * static_cast<std::uint64_t>(k)) % (1ull << 32), values(a.x(), a.y(), a.z()),
                 values(g.x(), g.y(), g.z()));
  }
  return s;
}

/// A plain csv table `t, gx, gy, gz, ax, ay, az` at 100 Hz, `n` rows.
std::string csv_rows(int n, int first = 0) {
  std::string s;
  for (int k = first; k < first + n; ++k) {
    std::ostringstream l;
    l.precision(17);
    l << 0.01 * k << "," << 0.1 << "," << -0.2 << "," << 0.001 * k << "," << 0.3 << "," << -9.8 << "," << 0.05 << "\n";
    s += l.str();
  }
  return s;
}

std::string joined(const std::vector<std::string>& notes) {
  std::string s;
  for (const auto& n : notes) s += n + "\n";
  return s;
}

bool any_file_with(const fs::path& dir, const std::string& part) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().filename().string().find(part) != std::string::npos) return true;
  return false;
}

fs::path shared_dir() {
  if (const char* env = std::getenv("WHEELINS_SHARED_DIR")) return env;
  return fs::path(WHEELINS_SOURCE_DIR) / ".." / "shared";
}

}  // namespace

// ------------------------------------------------------------------------------ column maps

TEST(TableColumnMap, PresetsValidatePrintAndParseBack) {
  for (const auto& name : column_map_preset_names()) {
    const ColumnMap m = column_map_preset(name);
    EXPECT_NO_THROW(m.validate()) << name;
    EXPECT_EQ(m.preset, name);
    EXPECT_EQ(parse_column_map(m.to_string()), m) << name << ": " << m.to_string();
    EXPECT_HAS(m.describe(), "preset " + name);
  }
  EXPECT_EQ(ColumnMap{}, column_map_preset("csv"));
  const std::string e = error_of([] { column_map_preset("xsens-dto"); });
  EXPECT_HAS(e, "unknown column map preset 'xsens-dto'");
  EXPECT_HAS(e, "did you mean 'xsens-dot'?");
}

TEST(TableColumnMap, XsensDotPresetIsTheExportAsShipped) {
  const ColumnMap m = column_map_preset("xsens-dot");
  EXPECT_EQ(m.delimiter, Delimiter::kComma);
  EXPECT_EQ(m.skip_lines, -1);
  EXPECT_EQ(m.header, HeaderMode::kYes);
  EXPECT_EQ(m.time.name, "SampleTimeFine");
  EXPECT_EQ(m.time_unit, TimeUnit::kMicrosecond);
  EXPECT_EQ(m.time_wrap, 1ull << 32);
  EXPECT_EQ(m.gyro[0].name, "Gyr_X");
  EXPECT_EQ(m.gyro[2].name, "Gyr_Z");
  EXPECT_EQ(m.accel[1].name, "Acc_Y");
  EXPECT_EQ(m.gyro_unit, GyroUnit::kDegPerSecond);
  EXPECT_EQ(m.accel_unit, AccelUnit::kMeterPerSecond2);
  EXPECT_EQ(m.gyro_range_dps, 2000.0);
  EXPECT_DOUBLE_EQ(m.accel_range_m_s2, 16 * 9.80665);
  EXPECT_NEAR(m.gyro_limit(), 2100.0 * kDeg, 1e-12);
  EXPECT_NEAR(m.accel_limit(), 16 * 9.80665 * 1.05, 1e-12);
  EXPECT_HAS(m.describe(), "'SampleTimeFine' [us], a counter wrapping at 2^32 ticks");
  EXPECT_HAS(m.describe(), "+-2000 deg/s");
  EXPECT_HAS(m.describe(), "(16 g)");
}

TEST(TableColumnMap, CommandLineString) {
  const ColumnMap m =
      parse_column_map("t=SampleTimeFine:us,gyro=Gyr_X,Gyr_Y,Gyr_Z:deg/s,accel=Acc_X,Acc_Y,Acc_Z:m/s^2");
  EXPECT_EQ(m.time, (ColumnRef{"SampleTimeFine", -1}));
  EXPECT_EQ(m.time_unit, TimeUnit::kMicrosecond);
  EXPECT_EQ(m.gyro[1], (ColumnRef{"Gyr_Y", -1}));
  EXPECT_EQ(m.gyro_unit, GyroUnit::kDegPerSecond);
  EXPECT_EQ(m.accel[2], (ColumnRef{"Acc_Z", -1}));
  EXPECT_EQ(m.accel_unit, AccelUnit::kMeterPerSecond2);
  // Indices, the other keys, spaces around items.
  const ColumnMap n = parse_column_map(
      "delimiter=semicolon, skip_lines=2, header=false, time=3:ms, time_wrap=2^16, time_scale=0.5, "
      "gyro=0,1,2, gyro_range_dps=500, accel=4,5,6:g, accel_range_m_s2=78.4532");
  EXPECT_EQ(n.delimiter, Delimiter::kSemicolon);
  EXPECT_EQ(n.skip_lines, 2);
  EXPECT_EQ(n.header, HeaderMode::kNo);
  EXPECT_EQ(n.time, (ColumnRef{"", 3}));
  EXPECT_EQ(n.time_unit, TimeUnit::kMillisecond);
  EXPECT_EQ(n.time_wrap, 65536u);
  EXPECT_EQ(n.time_scale, 0.5);
  EXPECT_EQ(n.gyro[0], (ColumnRef{"", 0}));
  EXPECT_EQ(n.gyro_range_dps, 500.0);
  EXPECT_EQ(n.accel_unit, AccelUnit::kStandardGravity);
  EXPECT_EQ(n.accel_range_m_s2, 78.4532);
  EXPECT_EQ(parse_column_map(n.to_string()), n);
  EXPECT_EQ(parse_column_map(""), ColumnMap{});
}

TEST(TableColumnMap, APresetRefinedByAString) {
  const ColumnMap dot = column_map_preset("xsens-dot");
  ColumnMap m = parse_column_map("gyro_unit=rad/s", dot);
  ColumnMap expected = dot;
  expected.gyro_unit = GyroUnit::kRadPerSecond;
  EXPECT_EQ(m, expected);
  EXPECT_EQ(column_map_from_options("xsens-dot", "gyro_unit=rad/s"), expected);
  // The string may name the preset itself; naming another than --preset is an error.
  EXPECT_EQ(column_map_from_options("", "preset=xsens-dot,gyro_unit=rad/s"), expected);
  EXPECT_HAS(error_of([] { column_map_from_options("csv", "preset=xsens-dot"); }),
             "names preset 'xsens-dot' but --preset csv was given");
  EXPECT_EQ(column_map_from_options("xsens-dot", ""), dot);
  EXPECT_EQ(column_map_from_options("", ""), ColumnMap{});
  // auto gives a unit back to the file.
  EXPECT_FALSE(parse_column_map("gyro_unit=auto", dot).gyro_unit.has_value());
}

TEST(TableColumnMap, StringErrorsNameTheKey) {
  EXPECT_HAS(error_of([] { parse_column_map("gyro_units=deg/s"); }), "unknown key 'gyro_units'; did you mean 'gyro_unit'?");
  EXPECT_HAS(error_of([] { parse_column_map("gyro=a,b"); }), "gyro: expected 3 columns (x, y, z), got 2");
  EXPECT_HAS(error_of([] { parse_column_map("gyro=a,b,c:furlong/s"); }), "gyro_unit: unknown unit 'furlong/s'");
  EXPECT_HAS(error_of([] { parse_column_map("time=1,time=2"); }), "key 'time' given twice");
  EXPECT_HAS(error_of([] { parse_column_map("t=1,time=2"); }), "key 'time' given twice");
  EXPECT_HAS(error_of([] { parse_column_map("time=x:us,time_unit=ms"); }), "give one of them");
  EXPECT_HAS(error_of([] { parse_column_map("time=1"); }), "gyro[0]: column 1 is already time's");
  EXPECT_HAS(error_of([] { parse_column_map("header=false,time=T"); }), "time: names column 'T' but the map says");
  EXPECT_HAS(error_of([] { parse_column_map("time_wrap=2^63"); }), "time_wrap: expected a counter wrap");
  EXPECT_HAS(error_of([] { parse_column_map("time_scale=0"); }), "time_scale: must be in");
  EXPECT_HAS(error_of([] { parse_column_map("gyro_range_dps=3"); }), "must be 0 (not stated) or in [10, 100000] deg/s");
  EXPECT_HAS(error_of([] { parse_column_map("delimiter=pipe"); }), "expected auto, comma, semicolon, tab or blanks");
  EXPECT_HAS(error_of([] { parse_column_map("skip_lines=-3"); }), "skip_lines: expected auto");
  EXPECT_HAS(error_of([] { parse_column_map("gyro=1,,3"); }), "an empty item");
  EXPECT_HAS(error_of([] { parse_column_map("foo"); }), "'foo' is not key=value");
  EXPECT_HAS(error_of([] { parse_column_map("time=99999"); }), "beyond the largest accepted");
  EXPECT_HAS(error_of([] { parse_column_map("preset=nope"); }), "unknown column map preset 'nope'");
  EXPECT_HAS(error_of([] { parse_column_map("gyro=a:b,c,d"); }), "gyro: column 'a:b' has a ':'");
}

TEST(TableColumnMap, YamlFileRefinesAPresetAndWarnsAboutUnknownKeys) {
  ScratchDir dir;
  write_text(dir / "dot.yaml",
             "preset: xsens-dot\n"
             "gyro_unit: rad/s\n"
             "accel: [AccX, AccY, AccZ]\n"
             "accel_unit: g\n"
             "time_wrap: \"2^31\"\n"
             "delimter: semicolon\n");
  std::vector<std::string> warnings;
  const ColumnMap m = load_column_map(dir / "dot.yaml", ColumnMap{}, [&](const std::string& w) { warnings.push_back(w); });
  ColumnMap expected = column_map_preset("xsens-dot");
  expected.gyro_unit = GyroUnit::kRadPerSecond;
  expected.accel = {ColumnRef{"AccX", -1}, ColumnRef{"AccY", -1}, ColumnRef{"AccZ", -1}};
  expected.accel_unit = AccelUnit::kStandardGravity;
  expected.time_wrap = 1ull << 31;
  EXPECT_EQ(m, expected);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_HAS(warnings[0], "delimter: unknown key ignored (line 6); did you mean 'delimiter'?");
  // The same through the options the CLI takes (a file name).
  EXPECT_EQ(column_map_from_options("", (dir / "dot.yaml").string(), [](const std::string&) {}), expected);
  EXPECT_TRUE(is_column_map_file((dir / "dot.yaml").string()));
  EXPECT_FALSE(is_column_map_file("t=a,gyro=b,c,d"));

  write_text(dir / "bad.yaml", "time: SampleTimeFine\ngyro: Gyr_X\n");
  std::string e = error_of([&] { load_column_map(dir / "bad.yaml"); });
  EXPECT_HAS(e, "bad.yaml': gyro: expected a list of 3 columns [x, y, z], got 'Gyr_X' (line 2)");
  write_text(dir / "bad2.yaml", "gyro_range_dps: 1e9\n");
  e = error_of([&] { load_column_map(dir / "bad2.yaml"); });
  EXPECT_HAS(e, "bad2.yaml': gyro_range_dps: must be 0 (not stated) or in [10, 100000] deg/s, got 1e9 (line 1)");
  write_text(dir / "bad3.yaml", "accel: [0, 1, 2]\n");  // collides with the csv preset's time and gyro
  e = error_of([&] { load_column_map(dir / "bad3.yaml"); });
  EXPECT_HAS(e, "bad3.yaml': column map: accel[0]: column 0 is already time's");
  e = error_of([&] { load_column_map(dir / "missing.yaml"); });
  EXPECT_HAS(e, "missing.yaml': column map file not found");
}

// ------------------------------------------------------------------------------ the reader

TEST(TableReader, XsensDotExportWithEveryKindOfBadRow) {
  ScratchDir dir;
  const std::uint64_t t0 = (1ull << 32) - 8333ull * 100;  // the counter wraps after row 99
  const int n = 300;
  std::map<int, std::string> bad;
  bad[0] = dot_row(0, t0, "0, 0, 0", "0, 0, 0");                                     // before the first sample
  bad[20] = dot_row(20, t0 + 20 * 8333, "NaN, NaN, NaN", "Infinity, -Infinity, -Infinity");
  bad[40] = dot_row(40, t0 + 39 * 8333, values(0.5, -9.8, 1.5), values(1, 2, 3));     // repeats row 39's time
  bad[60] = dot_row(60, t0 + 60 * 8333, values(0.5, 1e30, 1.5), values(1, 2, 3));     // absurd
  bad[150] = dot_row(150, (t0 + 150 * 8333) % (1ull << 32), values(0.5, -9.8, 1.5), values(1, 2, 1e8));
  const fs::path file = dir / "IMU2_radial.csv";
  write_text(file, dot_text(n, t0, bad));

  const ReadAll r = read_all(file, column_map_preset("xsens-dot"));
  const TableSummary& s = r.summary;
  EXPECT_EQ(s.rows_read, 300u);
  EXPECT_EQ(s.rows_kept, 295u);
  ASSERT_EQ(r.rows.size(), 295u);
  EXPECT_EQ(s.faults[RowFault::kAllZero], 1u);
  EXPECT_EQ(s.faults.first_of(RowFault::kAllZero).row, 0u);
  EXPECT_EQ(s.faults.first_of(RowFault::kAllZero).line, 3u);  // sep line, header, then row 0
  EXPECT_EQ(s.faults[RowFault::kNonFinite], 1u);
  EXPECT_EQ(s.faults.first_of(RowFault::kNonFinite).row, 20u);
  EXPECT_EQ(s.faults.first_of(RowFault::kNonFinite).line, 23u);
  EXPECT_HAS(s.faults.first_of(RowFault::kNonFinite).what, "column 5 (Acc_X) is NaN");
  EXPECT_EQ(s.faults[RowFault::kTimeNotIncreasing], 1u);
  EXPECT_EQ(s.faults.first_of(RowFault::kTimeNotIncreasing).row, 40u);
  EXPECT_HAS(s.faults.first_of(RowFault::kTimeNotIncreasing).what, "repeats the time of the previous kept row (row 39");
  EXPECT_EQ(s.faults[RowFault::kBeyondRange], 2u);
  EXPECT_EQ(s.faults.first_of(RowFault::kBeyondRange).row, 60u);
  EXPECT_HAS(s.faults.first_of(RowFault::kBeyondRange).what, "column 6 (Acc_Y) = 1e+30 m/s^2, beyond the limit 164.752 m/s^2 (the stated range + 5 %)");
  EXPECT_EQ(s.faults[RowFault::kColumns] + s.faults[RowFault::kUnparsable], 0u);
  EXPECT_EQ(s.faults.total(), 5u);

  // The kept rows: the counter unwrapped (row 100 is past 2^32 us), deg/s to rad/s.
  std::size_t i = 0;
  for (int k = 0; k < n; ++k) {
    if (bad.count(k)) continue;
    const ImuRow& row = r.rows[i++];
    const double t = static_cast<double>(t0 + 8333ull * static_cast<std::uint64_t>(k)) * 1e-6;
    ASSERT_NEAR(row.t, t, 1e-9) << "row " << k;
    EXPECT_NEAR(row.gyro.x(), dot_gyro(k).x() * kPi / 180.0, 1e-15);
    EXPECT_NEAR(row.gyro.z(), dot_gyro(k).z() * kPi / 180.0, 1e-15);
    EXPECT_EQ(row.accel.y(), dot_accel(k).y());
  }
  EXPECT_GT(r.rows[200].t, 4294.967296);  // after the wrap, beyond 2^32 us
  EXPECT_NEAR(s.timing.interval_median, 8333e-6, 1e-12);
  EXPECT_NEAR(s.timing.rate_hz(), 1e6 / 8333.0, 1e-6);
  EXPECT_NEAR(s.timing.interval_max, 2 * 8333e-6, 1e-12);  // the left-out rows leave double intervals
  EXPECT_EQ(s.timing.gap_count, 0u);
  EXPECT_NEAR(s.timing.t_first, (t0 + 8333) * 1e-6, 1e-9);
  EXPECT_NEAR(s.timing.span(), 298 * 8333e-6, 1e-9);
  EXPECT_EQ(s.map.gyro_unit, GyroUnit::kDegPerSecond);

  // 5 of 300 rows (1.7 %) is more than the default limit of 1 %: an error naming it all.
  const std::string e = error_of([&] { read_all(file, column_map_preset("xsens-dot"), 0.01); });
  EXPECT_HAS(e, "IMU2_radial.csv': 5 of 300 data rows (1.67 %) cannot be samples, more than the limit of 1 %");
  EXPECT_HAS(e, "1 NaN or infinite (first: data row 20 (0-based), line 23: column 5 (Acc_X) is NaN)");
  EXPECT_HAS(e, "1 all zero (first: data row 0 (0-based), line 3:");
  EXPECT_HAS(e, "2 beyond range (first: data row 60 (0-based), line 63:");
  EXPECT_HAS(e, "1 time not increasing (first: data row 40 (0-based), line 43:");
}

TEST(TableReader, WrongColumnCount) {
  ScratchDir dir;
  write_text(dir / "a.csv", csv_rows(5) + "0.05,1,2,3,4,5\n" + csv_rows(4, 6) + "0.1,0.1,-0.2,0.01,0.3,-9.8,0.05,7,8\n");
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
  EXPECT_EQ(r.summary.rows_read, 11u);
  EXPECT_EQ(r.summary.rows_kept, 10u);  // extra fields are fine
  EXPECT_EQ(r.summary.faults[RowFault::kColumns], 1u);
  EXPECT_EQ(r.summary.faults.first_of(RowFault::kColumns).row, 5u);
  EXPECT_EQ(r.summary.faults.first_of(RowFault::kColumns).line, 6u);
  EXPECT_HAS(r.summary.faults.first_of(RowFault::kColumns).what, "6 fields, the column map needs 7 (up to column 6");
}

TEST(TableReader, UnparsableValues) {
  ScratchDir dir;
  write_text(dir / "a.csv", csv_rows(3) + "0.03,0.1,abc,0,0.3,-9.8,0.05\n0.04,0.1,,0,0.3,-9.8,0.05\n" +
                                "0.045,+-1,0,0,0.3,-9.8,0.05\n" + csv_rows(3, 5));
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
  EXPECT_EQ(r.summary.faults[RowFault::kUnparsable], 3u);
  EXPECT_EQ(r.summary.rows_kept, 6u);
  EXPECT_EQ(r.summary.faults.first_of(RowFault::kUnparsable).row, 3u);
  EXPECT_HAS(r.summary.faults.first_of(RowFault::kUnparsable).what, "column 2 (gyro[1]): cannot read 'abc' as a number");
  // A counter outside its wrap, and a time beyond what a double holds in seconds.
  write_text(dir / "b.csv", "65535,1,2,3,4,5,6\n65536,1,2,3,4,5,6\n3,1,2,3,4,5,6\n1e303,1,2,3,4,5,6\n");
  const ReadAll c = read_all(dir / "b.csv", parse_column_map("time_wrap=2^16,time_scale=1e6"));
  EXPECT_EQ(c.summary.faults[RowFault::kUnparsable], 2u);
  EXPECT_HAS(c.summary.faults.first_of(RowFault::kUnparsable).what, "counter value 65536 is outside [0, 65536)");
  ASSERT_EQ(c.rows.size(), 2u);
  EXPECT_EQ(c.rows[1].t, (65536.0 + 3.0) * 1e6);  // wrapped once
  const ReadAll d = read_all(dir / "b.csv", parse_column_map("time_scale=1e6"));
  EXPECT_EQ(d.summary.faults[RowFault::kUnparsable], 1u);
  EXPECT_HAS(d.summary.faults.first_of(RowFault::kUnparsable).what, "1e303 is beyond the seconds a double holds");
}

TEST(TableReader, NonFiniteSpellings) {
  ScratchDir dir;
  std::string text = csv_rows(2);
  const char* spellings[] = {"NaN", "nan", "Infinity", "-Infinity", "inf", "-INF"};
  int k = 2;
  for (const char* s : spellings) text += std::to_string(0.01 * k++) + ",0.1," + s + ",0,0.3,-9.8,0.05\n";
  text += "NaN,0.1,0.2,0,0.3,-9.8,0.05\n";  // the time itself
  text += csv_rows(2, 9);
  write_text(dir / "a.csv", text);
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
  EXPECT_EQ(r.summary.faults[RowFault::kNonFinite], 7u);
  EXPECT_EQ(r.summary.faults[RowFault::kUnparsable], 0u);
  EXPECT_EQ(r.summary.rows_kept, 4u);
  EXPECT_HAS(r.summary.faults.first_of(RowFault::kNonFinite).what, "column 2 (gyro[1]) is NaN");
}

TEST(TableReader, AllZeroRows) {
  ScratchDir dir;
  write_text(dir / "a.csv", "0,0,0,0,0,0,0\n" + csv_rows(3, 1) + "0.04,0,0,0,0,-0,0.0\n0.05,0,0,0,0,0,1e-9\n");
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
  EXPECT_EQ(r.summary.faults[RowFault::kAllZero], 2u);
  EXPECT_EQ(r.summary.faults.first_of(RowFault::kAllZero).row, 0u);
  EXPECT_EQ(r.summary.rows_kept, 4u);  // 1e-9 is not zero
  EXPECT_DOUBLE_EQ(r.rows.back().accel.z(), 1e-9);
}

TEST(TableReader, BeyondTheSensorsRange) {
  ScratchDir dir;
  // gyro 2000 deg/s range: 2099 deg/s is within + 5 %, 2101 is not; 1e400 overflows.
  write_text(dir / "a.csv", "# units: s, deg/s, m/s^2\n" + csv_rows(2) + "0.02,2099,0,0,0,0,9.8\n0.03,-2101,0,0,0,0,9.8\n" +
                                "0.04,1,0,0,1e400,0,9.8\n0.05,1,0,0,0,0,170\n0.06,1,0,0,0,0,164\n");
  ColumnMap m;
  m.gyro_range_dps = 2000;
  m.accel_range_m_s2 = 16 * kStandardGravity;
  const ReadAll r = read_all(dir / "a.csv", m);
  EXPECT_EQ(r.summary.faults[RowFault::kBeyondRange], 3u);
  EXPECT_EQ(r.summary.faults.first_of(RowFault::kBeyondRange).row, 3u);
  EXPECT_HAS(r.summary.faults.first_of(RowFault::kBeyondRange).what, "column 1 (gyro[0]) = -2101 deg/s, beyond the limit 2100 deg/s");
  EXPECT_EQ(r.summary.rows_kept, 4u);
  // Without a stated range only absurd values are faults (20000 deg/s, 2000 m/s^2).
  const ReadAll d = read_all(dir / "a.csv", ColumnMap{});
  EXPECT_EQ(d.summary.faults[RowFault::kBeyondRange], 1u);
  EXPECT_HAS(d.summary.faults.first_of(RowFault::kBeyondRange).what, "no sensor reads more");
}

TEST(TableReader, TimeThatDoesNotIncrease) {
  ScratchDir dir;
  write_text(dir / "a.csv", csv_rows(4) + csv_rows(1, 3) + csv_rows(1, 1) + csv_rows(3, 4));
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
  EXPECT_EQ(r.summary.faults[RowFault::kTimeNotIncreasing], 2u);
  EXPECT_EQ(r.summary.faults.first_of(RowFault::kTimeNotIncreasing).row, 4u);
  EXPECT_HAS(r.summary.faults.first_of(RowFault::kTimeNotIncreasing).what, "repeats the time of the previous kept row (row 3");
  EXPECT_EQ(r.summary.rows_kept, 7u);
  for (std::size_t i = 1; i < r.rows.size(); ++i) EXPECT_GT(r.rows[i].t, r.rows[i - 1].t);
}

TEST(TableReader, UnitsLineConvertsDegreesAndG) {
  ScratchDir dir;
  write_text(dir / "a.csv", "# recorded by a logger\n# units: ms, deg/s, g\nt,gx,gy,gz,ax,ay,az\n"
                            "10,90,-180,0,1,0,-0.5\n20,45,0,0,0,2,0\n");
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_NEAR(r.rows[0].t, 0.010, 1e-15);
  EXPECT_NEAR(r.rows[1].t, 0.020, 1e-15);
  EXPECT_NEAR(r.rows[0].gyro.x(), kPi / 2, 1e-15);
  EXPECT_NEAR(r.rows[0].gyro.y(), -kPi, 1e-15);
  EXPECT_NEAR(r.rows[1].gyro.x(), kPi / 4, 1e-15);
  EXPECT_DOUBLE_EQ(r.rows[0].accel.x(), 9.80665);
  EXPECT_DOUBLE_EQ(r.rows[0].accel.z(), -0.5 * 9.80665);
  EXPECT_DOUBLE_EQ(r.rows[1].accel.y(), 2 * 9.80665);
  EXPECT_EQ(r.summary.map.time_unit, TimeUnit::kMillisecond);
  EXPECT_EQ(r.summary.map.accel_unit, AccelUnit::kStandardGravity);
  EXPECT_HAS(joined(r.summary.notes), "gyro in deg/s, from the units line (line 2)");
  // One unit per column works too ('-' for none).
  write_text(dir / "b.csv", "# units: s, dps, dps, dps, m/s^2, m/s^2, m/s^2\n1,180,0,0,0,0,9.8\n2,0,0,0,0,0,9.8\n");
  EXPECT_NEAR(read_all(dir / "b.csv", ColumnMap{}).rows[0].gyro.x(), kPi, 1e-15);
  write_text(dir / "c.csv", "# units: s, furlongs\n1,180,0,0,0,0,9.8\n2,0,0,0,0,0,9.8\n");
  EXPECT_HAS(error_of([&] { read_all(dir / "c.csv", ColumnMap{}); }), "the units line (line 1): 'furlongs' is not a gyro unit");
}

TEST(TableReader, UnitsInHeaderNames) {
  ScratchDir dir;
  write_text(dir / "a.csv", "time[us],gyro_x[deg/s],gyro_y[deg/s],gyro_z[deg/s],acc_x (g),acc_y (g),acc_z (g)\n"
                            "1000000,-90,0,30,0,0,1\n1010000,0,0,0,0.5,0,1\n");
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_DOUBLE_EQ(r.rows[0].t, 1.0);
  EXPECT_NEAR(r.rows[1].t, 1.01, 1e-15);
  EXPECT_NEAR(r.rows[0].gyro.x(), -kPi / 2, 1e-15);
  EXPECT_NEAR(r.rows[0].gyro.z(), kPi / 6, 1e-15);
  EXPECT_DOUBLE_EQ(r.rows[0].accel.z(), 9.80665);
  EXPECT_DOUBLE_EQ(r.rows[1].accel.x(), 0.5 * 9.80665);
  // Columns by name match the name without its unit.
  const ColumnMap by_name = parse_column_map("time=time,gyro=gyro_x,gyro_y,gyro_z,accel=acc_x,acc_y,acc_z (g)");
  EXPECT_NEAR(read_all(dir / "a.csv", by_name).rows[0].gyro.x(), -kPi / 2, 1e-15);
  // The map's unit wins over the file's, with a warning.
  std::vector<std::string> warnings;
  const ReadAll o = read_all(dir / "a.csv", parse_column_map("gyro_unit=rad/s"), 1.0,
                             [&](const std::string& w) { warnings.push_back(w); });
  EXPECT_DOUBLE_EQ(o.rows[0].gyro.x(), -90.0);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_HAS(warnings[0], "the header name 'gyro_x[deg/s]' says gyro in deg/s, the column map says rad/s; reading rad/s");
}

TEST(TableReader, DefaultUnitsWithoutHeader) {
  ScratchDir dir;
  write_text(dir / "a.txt", "1.0 0.1 0.2 0.3 1 2 9.8\n1.005 0.1 0.2 0.3 1 2 9.8\n");
  const ReadAll r = read_all(dir / "a.txt", ColumnMap{});
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_EQ(r.rows[1].t, 1.005);
  EXPECT_EQ(r.rows[1].gyro.z(), 0.3);
  EXPECT_EQ(r.rows[1].accel.z(), 9.8);
  EXPECT_EQ(r.summary.map.delimiter, Delimiter::kBlanks);
  EXPECT_EQ(r.summary.map.header, HeaderMode::kNo);
  EXPECT_HAS(joined(r.summary.notes), "time in s (the default: no unit stated)");
}

TEST(TableReader, DelimitersAreDetected) {
  ScratchDir dir;
  const std::string rows[] = {"t;gx;gy;gz;ax;ay;az\n0;1;2;3;4;5;6\n1;1;2;3;4;5;6\n",
                              "t\tgx\tgy\tgz\tax\tay\taz\n0\t1\t2\t3\t4\t5\t6\n1\t1\t2\t3\t4\t5\t6\n",
                              "sep=;\n\"t\";\"gx\";\"gy\";\"gz\";\"ax\";\"ay\";\"az\"\n0;1;2;3;4;5;6\n1;1;2;3;4;5;6\n"};
  const Delimiter expected[] = {Delimiter::kSemicolon, Delimiter::kTab, Delimiter::kSemicolon};
  for (int i = 0; i < 3; ++i) {
    write_text(dir / "a.csv", rows[i]);
    const ReadAll r = read_all(dir / "a.csv", ColumnMap{});
    ASSERT_EQ(r.rows.size(), 2u) << i;
    EXPECT_EQ(r.rows[1].accel.z(), 6.0) << i;
    EXPECT_EQ(r.summary.map.delimiter, expected[i]) << i;
  }
}

TEST(TableReader, ByteOrderMarkIsSkipped) {
  ScratchDir dir;
  write_text(dir / "a.csv", "\xEF\xBB\xBF" + std::string("sep=,\n") + kDotHeader + "\n" +
                                dot_row(1, 1000, "1, 2, 3", "4, 5, 6") + dot_row(2, 9333, "1, 2, 3", "4, 5, 6"));
  EXPECT_EQ(read_all(dir / "a.csv", column_map_preset("xsens-dot")).rows.size(), 2u);
  write_text(dir / "b.csv", "\xEF\xBB\xBF" + csv_rows(3));  // no header: the BOM is before a number
  EXPECT_EQ(read_all(dir / "b.csv", ColumnMap{}, 0.0).rows.size(), 3u);
}

TEST(TableReader, JitteryTimesAreKeptAsTheyAre) {
  ScratchDir dir;
  std::string text = "t,gx,gy,gz,ax,ay,az\n";
  std::vector<double> times;
  double t = 100.0;
  for (int k = 0; k < 400; ++k) {
    t += 0.005 + 0.0004 * std::sin(1.7 * k);  // 200 Hz with +-0.4 ms jitter
    if (k == 300) t += 0.1;                    // a gap of 20 intervals
    times.push_back(t);
    std::ostringstream l;
    l.precision(17);
    l << t << ",0.1,0.2,0.3,0,0,9.8\n";
    text += l.str();
  }
  write_text(dir / "a.csv", text);
  const ReadAll r = read_all(dir / "a.csv", ColumnMap{}, 0.0);
  ASSERT_EQ(r.rows.size(), times.size());
  for (std::size_t i = 0; i < times.size(); ++i) ASSERT_EQ(r.rows[i].t, times[i]) << i;  // not resampled
  const TableTiming& tm = r.summary.timing;
  EXPECT_NEAR(tm.interval_median, 0.005, 0.0001);
  EXPECT_NEAR(tm.interval_p05, 0.005 - 0.0004, 0.00003);
  EXPECT_NEAR(tm.interval_p95, 0.005 + 0.0004, 0.00003);
  EXPECT_NEAR(tm.jitter(), 0.0004, 0.00003);
  EXPECT_EQ(tm.gap_count, 1u);
  ASSERT_EQ(tm.gaps.size(), 1u);
  EXPECT_EQ(tm.gaps[0].row, 300u);
  EXPECT_EQ(tm.gaps[0].line, 302u);
  EXPECT_NEAR(tm.longest_gap, 0.105 + 0.0004 * std::sin(1.7 * 300), 1e-9);
  EXPECT_EQ(tm.t_first, times.front());
  EXPECT_EQ(tm.t_last, times.back());
}

TEST(TableReader, LongFilesBinTheirIntervals) {
  ScratchDir dir;
  // 20000 rows at exactly 8333 us (then a 10-interval gap), the DOT clock: binned quantiles
  // are exact for a regular clock.
  std::string text = "sep=,\n" + std::string(kDotHeader) + "\n";
  std::uint64_t t = 5000000;
  for (int k = 0; k < 20000; ++k) {
    t += k == 15000 ? 83330 : 8333;
    text += dot_row(k, t, "0.1, 0.2, 9.8", "1, 2, 3");
  }
  write_text(dir / "a.csv", text);
  const ReadAll r = read_all(dir / "a.csv", column_map_preset("xsens-dot"), 0.0);
  const TableTiming& tm = r.summary.timing;
  EXPECT_EQ(tm.intervals, 19999u);
  EXPECT_NEAR(tm.interval_median, 8333e-6, 1e-12);
  EXPECT_NEAR(tm.interval_p05, 8333e-6, 1e-12);
  EXPECT_NEAR(tm.interval_p95, 8333e-6, 1e-12);
  EXPECT_NEAR(tm.jitter(), 0.0, 1e-12);
  EXPECT_EQ(tm.gap_count, 1u);
  ASSERT_EQ(tm.gaps.size(), 1u);
  EXPECT_EQ(tm.gaps[0].row, 15000u);
  EXPECT_NEAR(tm.longest_gap, 0.08333, 1e-9);
}

TEST(TableReader, TooManyBadRowsOrNoneValid) {
  ScratchDir dir;
  write_text(dir / "a.csv", csv_rows(50) + "0.5,1,2\n0.51,x,0,0,0,0,0\n" + csv_rows(48, 52));
  const std::string e = error_of([&] { read_all(dir / "a.csv", ColumnMap{}, 0.01); });
  EXPECT_HAS(e, "a.csv': 2 of 100 data rows (2 %) cannot be samples, more than the limit of 1 % (--max-bad-fraction)");
  EXPECT_HAS(e, "1 wrong column count (first: data row 50 (0-based), line 51: 3 fields, the column map needs 7");
  EXPECT_HAS(e, "1 unparsable value (first: data row 51 (0-based), line 52: column 1 (gyro[0]): cannot read 'x' as a number)");
  EXPECT_EQ(read_all(dir / "a.csv", ColumnMap{}, 0.02).rows.size(), 98u);  // at the limit: accepted

  write_text(dir / "b.csv", "t,a,b\n1,2,3\n4,5,6\n");
  EXPECT_HAS(error_of([&] { read_all(dir / "b.csv", ColumnMap{}); }),
             "b.csv': none of its 2 data rows is a valid sample (at least 2 are needed): 2 wrong column count");
  write_text(dir / "c.csv", "t,gx,gy,gz,ax,ay,az\n");
  EXPECT_HAS(error_of([&] { read_all(dir / "c.csv", ColumnMap{}); }), "c.csv': has no data rows");
  write_text(dir / "d.csv", "");
  EXPECT_HAS(error_of([&] { read_all(dir / "d.csv", ColumnMap{}); }), "d.csv': has no data rows");
}

TEST(TableReader, HeaderAndFileErrors) {
  ScratchDir dir;
  write_text(dir / "a.csv", "sep=,\n" + std::string(kDotHeader) + "\n");
  const ColumnMap typo = parse_column_map("gyro=Gyr_X,Gyr_Y,Gyr_Zz", column_map_preset("xsens-dot"));
  const std::string e = error_of([&] { read_all(dir / "a.csv", typo); });
  EXPECT_HAS(e, "a.csv': line 2: no column 'Gyr_Zz' (gyro[2] in the column map) in the header; it has: PacketCounter, SampleTimeFine");
  EXPECT_HAS(e, "did you mean 'Gyr_Z'?");
  write_text(dir / "b.csv", "1,2,3,4,5,6,7\n");
  EXPECT_HAS(error_of([&] { read_all(dir / "b.csv", parse_column_map("time=T")); }),
             "names column 'T' (time) but the file has no header line");
  write_text(dir / "long.csv", "t,gx,gy,gz,ax,ay,az\n" + std::string(70000, '1') + "\n");
  EXPECT_HAS(error_of([&] { read_all(dir / "long.csv", ColumnMap{}); }), "long.csv': line 2: a line longer than 65536 characters");
  EXPECT_HAS(error_of([&] { read_all(dir / "none.csv", ColumnMap{}); }), "none.csv': file not found");
  EXPECT_HAS(error_of([&] { read_all(dir.path(), ColumnMap{}); }), "is a directory");
}

// ------------------------------------------------------------------------------ the import

TEST(TableImport, WritesTheImuFilesTheRunReads) {
  ScratchDir dir;
  write_text(dir / "in" / "IMU1.csv", dot_text(200, 715399356, {{0, dot_row(0, 715399356, "0, 0, 0", "0, 0, 0")}}));
  write_text(dir / "in" / "body.csv", "# units: s, deg/s, g\n" + csv_rows(150));
  std::vector<TableInput> in = {
      {module_name_from_file(dir / "in" / "IMU1.csv"), dir / "in" / "IMU1.csv", column_map_preset("xsens-dot")},
      {"body", dir / "in" / "body.csv", ColumnMap{}}};
  const auto out = import_tables(in, dir / "out");
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].module, "IMU1");
  EXPECT_EQ(out[0].output, dir / "out" / "IMU1_imu.bin");
  EXPECT_EQ(out[0].rows_read, 200u);
  EXPECT_EQ(out[0].rows_kept, 199u);
  EXPECT_EQ(out[0].faults[RowFault::kAllZero], 1u);
  EXPECT_NEAR(out[0].timing.rate_hz(), 120.0048, 1e-4);
  EXPECT_EQ(out[1].rows_kept, 150u);

  ImuReadOptions ro;
  ro.rate_hz = 120;
  ImuFileReader r(dir / "out" / "IMU1_imu.bin", ro);
  ImuSample s;
  int k = 1;
  while (r.next(s)) {
    EXPECT_NEAR(r.row().t, (715399356 + 8333.0 * k) * 1e-6, 1e-9);
    EXPECT_NEAR(r.row().gyro.y(), -20.5 * kPi / 180, 1e-15);
    EXPECT_EQ(r.row().accel.y(), dot_accel(k).y());
    ++k;
  }
  EXPECT_EQ(k, 200);
  EXPECT_EQ(fs::file_size(dir / "out" / "body_imu.bin"), 150u * 7 * 8);
  ImuFileReader b(dir / "out" / "body_imu.bin", ro);
  ASSERT_TRUE(b.next(s));
  ASSERT_TRUE(b.next(s));
  EXPECT_NEAR(b.row().gyro.x(), 0.1 * kPi / 180, 1e-15);
  EXPECT_DOUBLE_EQ(b.row().accel.y(), -9.8 * 9.80665);

  const std::string report = table_import_report(out);
  EXPECT_HAS(report, "file");
  EXPECT_HAS(report, "left out");
  EXPECT_HAS(report, "IMU1.csv  IMU1");
  EXPECT_HAS(report, "200        199");
  EXPECT_HAS(report, "120.005");
  EXPECT_HAS(report, "1 all zero (row 0)");
  EXPECT_HAS(report, "body.csv  body");
  EXPECT_HAS(report, "none");
}

TEST(TableImport, RefusesExistingOutputsUnlessOverwrite) {
  ScratchDir dir;
  write_text(dir / "a.csv", csv_rows(20));
  write_text(dir / "out" / "a_imu.bin", "earlier");
  write_text(dir / "out" / "keep.txt", "the user's");
  const std::vector<TableInput> in = {{"a", dir / "a.csv", ColumnMap{}}};
  EXPECT_HAS(error_of([&] { import_tables(in, dir / "out"); }), "a_imu.bin': already exists; refusing to overwrite it");
  EXPECT_EQ(fs::file_size(dir / "out" / "a_imu.bin"), 7u);
  TableImportOptions o;
  o.overwrite = true;
  import_tables(in, dir / "out", o);
  EXPECT_EQ(fs::file_size(dir / "out" / "a_imu.bin"), 20u * 56);
  EXPECT_TRUE(fs::exists(dir / "out" / "keep.txt"));
  // An input is never written over, even with overwrite.
  write_text(dir / "out2" / "x_imu.bin", csv_rows(20));
  const std::vector<TableInput> self = {{"x", dir / "out2" / "x_imu.bin", ColumnMap{}}};
  EXPECT_HAS(error_of([&] { import_tables(self, dir / "out2", o); }), "is an input of this import");
  EXPECT_EQ(fs::file_size(dir / "out2" / "x_imu.bin"), csv_rows(20).size());
  write_text(dir / "file", "x");
  EXPECT_HAS(error_of([&] { import_tables(in, dir / "file"); }), "is a file, expected the output directory");
}

TEST(TableImport, ModuleNames) {
  for (const char* bad : {"", "a/b", "..", "../x", ".hidden", "a b", "a..b", "a\\b", "IMU\n1"})
    EXPECT_THROW(check_module_name(bad), InputError) << bad;
  for (const char* good : {"IMU1_radial", "left-C1", "car.body", "x"}) EXPECT_NO_THROW(check_module_name(good)) << good;
  EXPECT_HAS(error_of([] { check_module_name("a/b"); }), "module name 'a/b': only letters, digits");
  EXPECT_HAS(error_of([] { check_module_name(""); }), "a module name is empty");
  EXPECT_EQ(module_name_from_file("/data/wmi-car/IMU1_radial.csv"), "IMU1_radial");
  EXPECT_EQ(module_name_from_file("left wheel (C1).txt"), "left_wheel__C1_");
  EXPECT_EQ(module_name_from_file("..hidden..csv.csv"), "_hidden_csv");
  EXPECT_EQ(module_name_from_file("/x/.y.csv"), "y");
  EXPECT_EQ(module_name_from_file("/"), "imu");
  for (const char* f : {"IMU1_radial.csv", "left wheel (C1).txt", "..hidden..csv.csv", "a..b.csv", "/x/.y.csv"})
    EXPECT_NO_THROW(check_module_name(module_name_from_file(f))) << f;

  ScratchDir dir;
  write_text(dir / "a.csv", csv_rows(5));
  EXPECT_HAS(error_of([&] { import_tables({{"../evil", dir / "a.csv", ColumnMap{}}}, dir / "out"); }),
             "module name '../evil'");
  EXPECT_HAS(error_of([&] { import_tables({{"a", dir / "a.csv", ColumnMap{}}, {"a", dir / "a.csv", ColumnMap{}}}, dir / "out"); }),
             "module name 'a' is given to two tables");
  EXPECT_FALSE(fs::exists(dir / "out"));
  EXPECT_HAS(error_of([&] { import_tables({}, dir / "out"); }), "no tables to import");
}

TEST(TableImport, NothingIsLeftBehindAfterAnError) {
  ScratchDir dir;
  write_text(dir / "good.csv", csv_rows(100));
  write_text(dir / "bad.csv", csv_rows(50) + "0.5,nan,0,0,0,0,0\n0.51,nan,0,0,0,0,0\n" + csv_rows(48, 52));
  const std::vector<TableInput> in = {{"good", dir / "good.csv", ColumnMap{}}, {"bad", dir / "bad.csv", ColumnMap{}}};
  // A new directory: removed again.
  EXPECT_HAS(error_of([&] { import_tables(in, dir / "new"); }), "bad.csv': 2 of 100 data rows (2 %)");
  EXPECT_FALSE(fs::exists(dir / "new"));
  // An existing directory: kept, with nothing of the import in it.
  fs::create_directories(dir / "old");
  write_text(dir / "old" / "notes.txt", "mine");
  EXPECT_HAS(error_of([&] { import_tables(in, dir / "old"); }), "NaN or infinite");
  EXPECT_FALSE(any_file_with(dir / "old", "_imu.bin"));
  EXPECT_TRUE(fs::exists(dir / "old" / "notes.txt"));
  // An exception from the progress callback (an interrupt) leaves nothing either.
  TableImportOptions o;
  o.max_bad_fraction = 0.05;
  o.progress = [](std::uint64_t done, std::uint64_t) {
    if (done > 0) throw std::runtime_error("interrupted");
  };
  std::string big = csv_rows(9000);
  write_text(dir / "big.csv", big);
  EXPECT_THROW(import_tables({{"good", dir / "good.csv", ColumnMap{}}, {"big", dir / "big.csv", ColumnMap{}}}, dir / "old", o),
               std::runtime_error);
  EXPECT_FALSE(any_file_with(dir / "old", "_imu.bin"));
  // With a higher limit the same tables import.
  o.progress = {};
  EXPECT_EQ(import_tables(in, dir / "old", o).size(), 2u);
  EXPECT_TRUE(fs::exists(dir / "old" / "bad_imu.bin"));
  EXPECT_FALSE(any_file_with(dir / "old", ".partial"));
}

TEST(TableImport, TemporariesOfAKilledImportAreRemoved) {
  ScratchDir dir;
  write_text(dir / "a.csv", csv_rows(10));
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  int status = 0;
  ::waitpid(child, &status, 0);  // a process id that is gone
  const fs::path stale = dir / "out" / ("a_imu.bin.partial-" + std::to_string(child) + "-0");
  const fs::path live = dir / "out" / ("a_imu.bin.partial-" + std::to_string(::getpid()) + "-999");
  write_text(stale, "half");
  write_text(live, "another writer's");
  import_tables({{"a", dir / "a.csv", ColumnMap{}}}, dir / "out");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(dir / "out" / "a_imu.bin"));
}

TEST(TableImport, ProgressCountsLines) {
  ScratchDir dir;
  write_text(dir / "a.csv", "t,gx,gy,gz,ax,ay,az\n" + csv_rows(10000));
  write_text(dir / "b.csv", csv_rows(5000));
  std::vector<std::pair<std::uint64_t, std::uint64_t>> calls;
  TableImportOptions o;
  o.progress = [&](std::uint64_t done, std::uint64_t total) { calls.emplace_back(done, total); };
  import_tables({{"a", dir / "a.csv", ColumnMap{}}, {"b", dir / "b.csv", ColumnMap{}}}, dir / "out", o);
  ASSERT_GE(calls.size(), 3u);
  for (std::size_t i = 0; i < calls.size(); ++i) {
    EXPECT_EQ(calls[i].second, 15001u);
    EXPECT_LE(calls[i].first, 15001u);
    if (i) {
      EXPECT_GE(calls[i].first, calls[i - 1].first);
    }
  }
  EXPECT_EQ(calls.back().first, 15001u);
}

// ------------------------------------------------------------------------------ real exports

TEST(TableImportShared, WmiCarTrial02XsensDotExports) {
  const fs::path trial = shared_dir() / "data" / "wmi-car" / "trial02";
  if (!fs::exists(trial / "IMU1.csv")) GTEST_SKIP() << "no shared wmi-car data at " << trial;
  ScratchDir dir;
  const char* names[] = {"IMU1", "IMU2", "IMU3", "IMU4", "IMU1_radial", "IMU2_radial", "IMU3_radial", "IMU4_radial", "CAR"};
  std::vector<TableInput> in;
  for (const char* n : names) {
    const fs::path f = trial / (std::string(n) + ".csv");
    in.push_back({module_name_from_file(f), f, column_map_preset("xsens-dot")});
  }
  const auto out = import_tables(in, dir / "out");
  ASSERT_EQ(out.size(), 9u);
  for (const auto& t : out) {
    SCOPED_TRACE(t.module);
    EXPECT_EQ(t.module, t.source.stem().string());
    EXPECT_GT(t.rows_read, 16000u);
    // Every export starts with an all-zero row: left out.
    EXPECT_GE(t.faults[RowFault::kAllZero], 1u);
    EXPECT_EQ(t.faults.first_of(RowFault::kAllZero).row, 0u);
    EXPECT_EQ(t.faults.first_of(RowFault::kAllZero).line, 3u);
    EXPECT_EQ(t.rows_kept, t.rows_read - t.faults.total());
    EXPECT_NEAR(t.timing.rate_hz(), 120.0, 0.01);
    EXPECT_NEAR(t.timing.interval_median, 8333e-6, 1e-9);
    EXPECT_GT(t.timing.span(), 130.0);
    EXPECT_LT(t.timing.span(), 140.0);
    EXPECT_EQ(t.timing.gap_count, 0u);
    EXPECT_EQ(fs::file_size(t.output), t.rows_kept * 56);
    EXPECT_GT(t.timing.t_first, 700.0);  // the sensor clock, in seconds since it started
  }
  // IMU2_radial: row 8 holds NaN and +-Infinity, and repeats row 7's time; row 7 comes two
  // intervals after row 6 (a dropped packet). The row counts once, as NaN or infinite.
  const ImportedTable& r2 = out[5];
  ASSERT_EQ(r2.module, "IMU2_radial");
  EXPECT_EQ(r2.faults[RowFault::kNonFinite], 1u);
  EXPECT_EQ(r2.faults.first_of(RowFault::kNonFinite).row, 8u);
  EXPECT_EQ(r2.faults.first_of(RowFault::kNonFinite).line, 11u);
  EXPECT_HAS(r2.faults.first_of(RowFault::kNonFinite).what, "column 5 (Acc_X) is NaN");
  EXPECT_EQ(r2.faults[RowFault::kTimeNotIncreasing], 0u);
  EXPECT_EQ(r2.faults.total(), 2u);
  EXPECT_NEAR(r2.timing.interval_max, 2 * 8333e-6, 1e-9);
  // The others have nothing else wrong.
  for (const auto& t : out)
    if (t.module != "IMU2_radial") {
      EXPECT_EQ(t.faults.total(), 1u) << t.module;
    }

  // Row 9 of IMU2_radial, read back from the binary file: the file's values in SI.
  ImuReadOptions ro;
  ro.rate_hz = 120;
  ImuFileReader rd(r2.output, ro);
  ImuSample s;
  for (int i = 0; i < 8; ++i) ASSERT_TRUE(rd.next(s));  // rows 1..7, then row 9
  EXPECT_NEAR(rd.row().t, 715.516018, 1e-9);
  EXPECT_NEAR(rd.row().accel.x(), -6.3427958488464355, 1e-12);
  EXPECT_NEAR(rd.row().gyro.x(), 1.4729467630386353 * kPi / 180, 1e-14);
}
