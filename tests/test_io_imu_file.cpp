#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>

#include "io_test_util.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/odometer.hpp"

// Counts heap allocations, to check that streaming allocates nothing per sample.
// (GCC flags the malloc/free pairing of a replaced operator new/delete once inlined.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
// The nothrow forms too (std::stable_sort's temporary buffer takes them): every form the
// program may use comes from this one allocator, or a sanitizer sees new and free mismatch.
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

using namespace wheelins;
using namespace wheelins::iotest;

namespace {

/// Rows at `rate` Hz from t0 with distinct, non-round values.
std::vector<ImuRow> make_rows(int n, double t0, double rate, double seed = 1.0) {
  std::vector<ImuRow> rows;
  for (int i = 0; i < n; ++i) {
    ImuRow r;
    r.t = t0 + i / rate;
    r.gyro = Vec3(std::sin(seed * i), 0.1 * std::cos(i + seed), -14.3 + 1e-3 * i);
    r.accel = Vec3(0.01 * i, -9.80665 + std::sin(i * 0.3), 1.0 / (i + seed));
    rows.push_back(r);
  }
  return rows;
}

std::vector<double> flatten(const std::vector<ImuRow>& rows) {
  std::vector<double> v;
  for (const auto& r : rows)
    v.insert(v.end(), {r.t, r.gyro.x(), r.gyro.y(), r.gyro.z(), r.accel.x(), r.accel.y(), r.accel.z()});
  return v;
}

void write_rows(const std::filesystem::path& file, const std::vector<ImuRow>& rows,
                FileLayout layout = FileLayout::kBinary, SampleFormat format = SampleFormat::kRate) {
  ImuFileWriter w(file, format, layout, true);
  for (const auto& r : rows) w.write_row(r);
  w.commit();
}

ImuReadOptions opts(FileLayout layout = FileLayout::kBinary, SampleFormat format = SampleFormat::kRate,
                    double rate = 200.0) {
  ImuReadOptions o;
  o.layout = layout;
  o.format = format;
  o.rate_hz = rate;
  return o;
}

std::string read_all_error(const std::filesystem::path& file, const ImuReadOptions& o = opts()) {
  return error_of([&] {
    ImuFileReader r(file, o);
    ImuSample s;
    while (r.next(s)) {
    }
  });
}

void expect_rows_equal(const ImuRow& a, const ImuRow& b) {
  EXPECT_EQ(a.t, b.t);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.gyro[k], b.gyro[k]);
    EXPECT_EQ(a.accel[k], b.accel[k]);
  }
}

}  // namespace

TEST(IoImuFile, BinaryAndTextRowsRoundTripExactly) {
  ScratchDir dir;
  const auto rows = make_rows(500, 132030.005, 200.0);
  for (FileLayout layout : {FileLayout::kBinary, FileLayout::kText}) {
    SCOPED_TRACE(to_string(layout));
    const auto file = dir / (std::string("imu.") + to_string(layout));
    write_rows(file, rows, layout);
    EXPECT_FALSE(iotest::partial_left(file));
    ImuFileReader r(file, opts(layout));
    EXPECT_EQ(r.first_time(), rows[0].t);
    ImuSample s;
    std::size_t i = 0;
    while (r.next(s)) {
      ASSERT_LT(i, rows.size());
      EXPECT_EQ(r.index(), i);
      expect_rows_equal(r.row(), rows[i]);
      const double dt = i == 0 ? 1.0 / 200.0 : rows[i].t - rows[i - 1].t;
      EXPECT_EQ(s.t, rows[i].t);
      EXPECT_EQ(s.dt, dt);
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(s.dtheta[k], rows[i].gyro[k] * dt);
        EXPECT_EQ(s.dvel[k], rows[i].accel[k] * dt);
      }
      ++i;
    }
    EXPECT_EQ(i, rows.size());
    EXPECT_EQ(r.gap_count(), 0u);
  }
}

TEST(IoImuFile, BinaryFileIsTheWheelInsLayout) {
  ScratchDir dir;
  const auto rows = make_rows(3, 10.0, 100.0);
  write_rows(dir / "a_imu.bin", rows);
  EXPECT_EQ(std::filesystem::file_size(dir / "a_imu.bin"), 3u * 7u * 8u);
  write_doubles(dir / "b_imu.bin", flatten(rows));  // written by hand, read by the reader
  ImuFileReader r(dir / "b_imu.bin", opts(FileLayout::kBinary, SampleFormat::kRate, 100.0));
  ImuSample s;
  for (const auto& row : rows) {
    ASSERT_TRUE(r.next(s));
    expect_rows_equal(r.row(), row);
  }
  EXPECT_FALSE(r.next(s));
}

TEST(IoImuFile, IncrementSamplesRoundTripExactly) {
  ScratchDir dir;
  for (FileLayout layout : {FileLayout::kBinary, FileLayout::kText}) {
    const auto file = dir / (std::string("inc.") + to_string(layout));
    std::vector<ImuSample> in;
    for (int i = 0; i < 300; ++i) {
      ImuSample s;
      s.t = 5.0 + i * 0.0025 + (i > 100 ? 0.001 : 0.0);
      s.dt = i == 0 ? 1.0 / 400.0 : s.t - in.back().t;
      s.dtheta = Vec3(1e-4 * i, -2e-5, 0.035 + 1e-7 * i);
      s.dvel = Vec3(0.0, 1e-3 * std::cos(i), -0.0245);
      in.push_back(s);
    }
    {
      ImuFileWriter w(file, SampleFormat::kIncrement, layout, true);
      for (const auto& s : in) w.write(s);
      EXPECT_EQ(w.rows(), in.size());
      w.commit();
    }
    ImuFileReader r(file, opts(layout, SampleFormat::kIncrement, 400.0));
    ImuSample s;
    for (const auto& e : in) {
      ASSERT_TRUE(r.next(s));
      EXPECT_EQ(s.t, e.t);
      EXPECT_EQ(s.dt, e.dt);
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(s.dtheta[k], e.dtheta[k]);
        EXPECT_EQ(s.dvel[k], e.dvel[k]);
      }
    }
    EXPECT_FALSE(r.next(s));
  }
}

TEST(IoImuFile, RateWriterStoresIncrementsOverDt) {
  ScratchDir dir;
  ImuSample s;
  s.t = 1.0;
  s.dt = 0.005;
  s.dtheta = Vec3(0.001, 0.002, -0.003);
  s.dvel = Vec3(0.0, 0.0, -0.049);
  {
    ImuFileWriter w(dir / "r.bin");
    w.write(s);
    ImuSample bad = s;
    bad.t = 2.0;
    bad.dt = 0.0;
    EXPECT_HAS(error_of([&] { w.write(bad); }), "a rate file needs dt > 0");
    w.commit();
  }
  ImuFileReader r(dir / "r.bin");
  ImuSample back;
  ASSERT_TRUE(r.next(back));
  EXPECT_EQ(r.row().gyro.x(), 0.001 / 0.005);
  EXPECT_EQ(r.row().accel.z(), -0.049 / 0.005);
}

TEST(IoImuFile, TimeOffsetIsApplied) {
  ScratchDir dir;
  write_rows(dir / "a.bin", make_rows(4, 100.0, 200.0));
  auto o = opts();
  o.time_offset = -0.25;
  ImuFileReader r(dir / "a.bin", o);
  EXPECT_EQ(r.first_time(), 100.0 - 0.25);
  ImuSample s;
  ASSERT_TRUE(r.next(s));
  EXPECT_EQ(s.t, 100.0 - 0.25);
  EXPECT_EQ(r.row().t, 100.0);
  ASSERT_TRUE(r.next(s));
  EXPECT_EQ(s.t, 100.005 - 0.25);
  EXPECT_EQ(s.dt, 100.005 - 100.0);
}

TEST(IoImuFile, TextLayoutAcceptsCommentsCommasAndBlankLines) {
  ScratchDir dir;
  write_text(dir / "a.csv",
             "# t, gx, gy, gz, ax, ay, az\n"
             "\n"
             "1.0, 0.1, 0.2, 0.3, 1, 2, 9.8   # first\r\n"
             "  1.005\t0.1 0.2 0.3 1 2 +9.8\n"
             "# a comment line\n"
             "1.01,0.1,0.2,0.3,1,2,-9.8e0\n");
  ImuFileReader r(dir / "a.csv", opts(FileLayout::kText));
  ImuSample s;
  int n = 0;
  while (r.next(s)) ++n;
  EXPECT_EQ(n, 3);
  EXPECT_EQ(r.row().t, 1.01);
  EXPECT_EQ(r.row().accel.z(), -9.8);
}

TEST(IoImuFile, NanAndInfNameFileRecordAndColumn) {
  ScratchDir dir;
  auto rows = make_rows(10, 0.0, 200.0);
  auto v = flatten(rows);
  v[3 * 7 + 4] = std::numeric_limits<double>::quiet_NaN();
  write_doubles(dir / "nan_imu.bin", v);
  const std::string msg = read_all_error(dir / "nan_imu.bin");
  EXPECT_HAS(msg, "nan_imu.bin': record 3 (0-based), column 4 (accel_x): value is NaN");

  v = flatten(rows);
  v[7 * 7 + 2] = -std::numeric_limits<double>::infinity();
  write_doubles(dir / "inf_imu.bin", v);
  EXPECT_HAS(read_all_error(dir / "inf_imu.bin"), "inf_imu.bin': record 7 (0-based), column 2 (gyro_y): value is infinite");

  write_text(dir / "nan.txt", "0 0 0 0 0 0 9.8\n0.005 0 nan 0 0 0 9.8\n");
  EXPECT_HAS(read_all_error(dir / "nan.txt", opts(FileLayout::kText)),
             "nan.txt': record 1 (0-based, line 2), column 2 (gyro_y): value is NaN");
}

TEST(IoImuFile, TimestampsMustStrictlyIncrease) {
  ScratchDir dir;
  auto rows = make_rows(10, 50.0, 200.0);
  rows[5].t = rows[4].t;
  write_doubles(dir / "rep.bin", flatten(rows));
  const std::string rep = read_all_error(dir / "rep.bin");
  EXPECT_HAS(rep, "rep.bin': record 5 (0-based), column 0 (t)");
  EXPECT_HAS(rep, "repeats the previous record's time");

  rows = make_rows(10, 50.0, 200.0);
  rows[6].t = rows[4].t;
  write_doubles(dir / "back.bin", flatten(rows));
  const std::string back = read_all_error(dir / "back.bin");
  EXPECT_HAS(back, "back.bin': record 6 (0-based), column 0 (t)");
  EXPECT_HAS(back, "goes back from the previous record's 50.025");
  EXPECT_HAS(back, "strictly increasing");

  // Issue 33, 3: times in milliseconds after the static period: a jump of 1e8 s is an error
  // at its record, not a gap to carry (the calibration pass ran out of memory over it).
  rows = make_rows(10, 100000.0, 200.0);
  for (std::size_t k = 6; k < rows.size(); ++k) rows[k].t *= 1000.0;
  write_doubles(dir / "ms.bin", flatten(rows));
  const std::string ms = read_all_error(dir / "ms.bin");
  EXPECT_HAS(ms, "ms.bin': record 6 (0-based), column 0 (t)");
  EXPECT_HAS(ms, "more than a day (are the times in another unit than seconds, e.g. milliseconds");
}

TEST(IoImuFile, MissingDirectoryTruncatedAndEmptyFiles) {
  ScratchDir dir;
  EXPECT_HAS(read_all_error(dir / "none_imu.bin"), "none_imu.bin': file not found");
  EXPECT_HAS(read_all_error(dir / "none.txt", opts(FileLayout::kText)), "none.txt': file not found");
  EXPECT_HAS(read_all_error(dir.path()), "is a directory");
  EXPECT_HAS(read_all_error(dir.path(), opts(FileLayout::kText)), "is a directory");
  auto v = flatten(make_rows(5, 0.0, 200.0));
  v.pop_back();
  write_doubles(dir / "trunc_imu.bin", v);
  const std::string trunc = read_all_error(dir / "trunc_imu.bin");
  EXPECT_HAS(trunc, "trunc_imu.bin'");
  EXPECT_HAS(trunc, "truncated");
  write_doubles(dir / "empty_imu.bin", {});
  EXPECT_HAS(read_all_error(dir / "empty_imu.bin"), "empty_imu.bin': contains no IMU records (empty file)");
  write_text(dir / "empty.txt", "# only a comment\n\n");
  EXPECT_HAS(read_all_error(dir / "empty.txt", opts(FileLayout::kText)), "empty.txt': contains no IMU records");
}

TEST(IoImuFile, UnreadableTextNamesLineAndColumn) {
  ScratchDir dir;
  write_text(dir / "bad.txt", "# header\n0 0 0 0 0 0 9.8\n\n0.005 0 0 0 x 0 9.8\n");
  EXPECT_HAS(read_all_error(dir / "bad.txt", opts(FileLayout::kText)),
             "bad.txt': record 1 (0-based, line 4), column 4 (accel_x): cannot read 'x' as a number");
  write_text(dir / "short.txt", "0 0 0 0 0 0 9.8\n0.005 0 0 0 0 9.8\n");
  EXPECT_HAS(read_all_error(dir / "short.txt", opts(FileLayout::kText)),
             "short.txt': record 1 (0-based, line 2): found 6 values, expected 7 columns");
  write_text(dir / "long.txt", "0 0 0 0 0 0 9.8 1\n");
  EXPECT_HAS(read_all_error(dir / "long.txt", opts(FileLayout::kText)),
             "long.txt': record 0 (0-based, line 1): more than 7 values");
  write_text(dir / "hdr.csv", "t,gx,gy,gz,ax,ay,az\n0 0 0 0 0 0 9.8\n");
  EXPECT_HAS(read_all_error(dir / "hdr.csv", opts(FileLayout::kText)), "a header line must start with '#'");
}

TEST(IoImuFile, GapsAreReportedThroughAccessorAndSink) {
  ScratchDir dir;
  auto rows = make_rows(100, 0.0, 100.0);
  // A 4-interval hole (below the default threshold of 5) and two real gaps.
  for (int i = 20; i < 100; ++i) rows[i].t += 0.03;
  for (int i = 50; i < 100; ++i) rows[i].t += 0.5;
  for (int i = 80; i < 100; ++i) rows[i].t += 1.0;
  write_rows(dir / "gap.bin", rows);
  std::vector<std::string> warnings;
  auto o = opts(FileLayout::kBinary, SampleFormat::kRate, 100.0);
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  ImuFileReader r(dir / "gap.bin", o);
  ImuSample s;
  while (r.next(s)) {
  }
  ASSERT_EQ(r.gap_count(), 2u);
  ASSERT_EQ(r.gaps().size(), 2u);
  EXPECT_EQ(r.gaps()[0].record, 50u);
  EXPECT_EQ(r.gaps()[0].t_before, rows[49].t);
  EXPECT_EQ(r.gaps()[1].record, 80u);
  EXPECT_NEAR(r.longest_gap(), 1.01, 1e-9);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_HAS(warnings[0], "gap.bin': record 50 (0-based): gap of");
  // With a limit, the rest are counted but not reported one by one.
  warnings.clear();
  o.max_gap_warnings = 1;
  ImuFileReader r2(dir / "gap.bin", o);
  while (r2.next(s)) {
  }
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_HAS(warnings[1], "further gaps are counted");
  EXPECT_EQ(r2.gap_count(), 2u);
  // Without a sink nothing is reported, but the accessor still knows.
  o.warn = nullptr;
  ImuFileReader r3(dir / "gap.bin", o);
  while (r3.next(s)) {
  }
  EXPECT_EQ(r3.gap_count(), 2u);
}

TEST(IoImuFile, WriterRefusesToOverwriteAndLeavesNothingWithoutCommit) {
  ScratchDir dir;
  write_rows(dir / "a.bin", make_rows(3, 0.0, 200.0));
  EXPECT_HAS(error_of([&] { ImuFileWriter w(dir / "a.bin"); }), "already exists");
  EXPECT_HAS(error_of([&] { ImuFileWriter w(dir / "a.txt", SampleFormat::kRate, FileLayout::kText); w.write_row({}); w.write_row({}); }),
             "a.txt': record 1 (0-based): time 0 is not after the previous record's 0");
  EXPECT_FALSE(std::filesystem::exists(dir / "a.txt"));
  EXPECT_FALSE(iotest::partial_left(dir / "a.txt"));
  ImuRow bad;
  bad.gyro.y() = std::nan("");
  EXPECT_HAS(error_of([&] { ImuFileWriter w(dir / "b.bin"); w.write_row(bad); }), "column 2 (gyro_y): value is not finite");
  EXPECT_FALSE(std::filesystem::exists(dir / "b.bin"));
}

namespace {
/// An in-memory stream for merger tests.
class VectorStream : public ImuStream {
 public:
  explicit VectorStream(std::vector<ImuSample> s) : s_(std::move(s)) {}
  bool next(ImuSample& out) override {
    if (i_ == s_.size()) return false;
    out = s_[i_++];
    return true;
  }

 private:
  std::vector<ImuSample> s_;
  std::size_t i_ = 0;
};

std::vector<ImuSample> times(std::initializer_list<double> ts) {
  std::vector<ImuSample> v;
  for (double t : ts) {
    ImuSample s;
    s.t = t;
    v.push_back(s);
  }
  return v;
}
}  // namespace

TEST(IoImuMerger, YieldsTimeOrderWithTiesInStreamOrder) {
  VectorStream a(times({1.0, 2.0, 3.0})), b(times({0.5, 2.0, 2.5, 10.0})), c(times({})), d(times({2.0}));
  ImuMerger m({&a, &b, &c, &d});
  std::vector<std::pair<std::size_t, double>> got;
  std::size_t k;
  ImuSample s;
  while (m.next(k, s)) got.emplace_back(k, s.t);
  const std::vector<std::pair<std::size_t, double>> want = {
      {1, 0.5}, {0, 1.0}, {0, 2.0}, {1, 2.0}, {3, 2.0}, {1, 2.5}, {0, 3.0}, {1, 10.0}};
  EXPECT_EQ(got, want);
  EXPECT_FALSE(m.next(k, s));
}

TEST(IoImuMerger, MergesFilesOfDifferentRatesWithoutAllocatingPerSample) {
  ScratchDir dir;
  Manifest man;
  man.path = dir / "manifest.yaml";
  const double rates[] = {200.0, 100.0, 125.0};
  const double starts[] = {10.0, 10.003, 9.5};
  std::vector<std::vector<ImuRow>> rows;
  for (int i = 0; i < 3; ++i) {
    rows.push_back(make_rows(4000, starts[i], rates[i], 1.0 + i));
    write_rows(dir / ("m" + std::to_string(i) + ".bin"), rows.back());
    ModuleSpec spec;
    spec.name = "m" + std::to_string(i);
    spec.file = "m" + std::to_string(i) + ".bin";
    spec.rate_hz = rates[i];
    spec.time_offset = i == 2 ? 0.25 : 0.0;
    man.modules.push_back(spec);
  }
  auto readers = open_imu_files(man);
  ImuMerger merger(stream_pointers(readers));
  ASSERT_EQ(merger.size(), 3u);
  std::size_t k;
  ImuSample s;
  std::vector<std::size_t> count(3, 0);
  double last_t = -1e300;
  const long before = g_allocations.load();
  while (merger.next(k, s)) {
    ASSERT_LT(k, 3u);
    ASSERT_GE(s.t, last_t);
    last_t = s.t;
    const ImuRow& want = rows[k][count[k]];
    ASSERT_EQ(s.t, want.t + (k == 2 ? 0.25 : 0.0));
    ++count[k];
  }
  const long after = g_allocations.load();
  EXPECT_EQ(after - before, 0) << "heap allocations while merging";
  for (int i = 0; i < 3; ++i) EXPECT_EQ(count[i], 4000u);
}

// ------------------------------------------------------------------------------ odometer

TEST(IoOdometer, BinaryAndTextRoundTripExactly) {
  ScratchDir dir;
  for (FileLayout layout : {FileLayout::kBinary, FileLayout::kText}) {
    const auto file = dir / (std::string("odo.") + to_string(layout));
    std::vector<OdoSample> in;
    for (int i = 0; i < 200; ++i) in.push_back({132030.005 + 0.5 * i, 1.4 * std::sin(0.01 * i) - 0.1});
    {
      OdoWriter w(file, layout);
      for (const auto& s : in) w.write(s);
      w.commit();
    }
    OdoReader r(file, layout);
    EXPECT_EQ(r.first_time(), in[0].t);
    OdoSample s;
    for (std::size_t i = 0; i < in.size(); ++i) {
      ASSERT_TRUE(r.next(s));
      EXPECT_EQ(r.index(), i);
      EXPECT_EQ(s.t, in[i].t);
      EXPECT_EQ(s.speed, in[i].speed);
    }
    EXPECT_FALSE(r.next(s));
  }
  EXPECT_EQ(std::filesystem::file_size(dir / "odo.binary"), 200u * 16u);
  OdoReader off(dir / "odo.binary", FileLayout::kBinary, 1.5);
  OdoSample s;
  ASSERT_TRUE(off.next(s));
  EXPECT_EQ(s.t, 132030.005 + 1.5);
}

TEST(IoOdometer, BadInputNamesFileRecordAndColumn) {
  ScratchDir dir;
  const auto read_all = [&](const std::filesystem::path& f, FileLayout l = FileLayout::kBinary) {
    return error_of([&] {
      OdoReader r(f, l);
      OdoSample s;
      while (r.next(s)) {
      }
    });
  };
  write_doubles(dir / "nan_odo.bin", {0.0, 1.0, 0.5, std::nan(""), 1.0, 1.2});
  EXPECT_HAS(read_all(dir / "nan_odo.bin"), "nan_odo.bin': record 1 (0-based), column 1 (speed): value is NaN");
  write_doubles(dir / "inf_odo.bin", {0.0, 1.0, HUGE_VAL, 1.0});
  EXPECT_HAS(read_all(dir / "inf_odo.bin"), "inf_odo.bin': record 1 (0-based), column 0 (t): value is infinite");
  write_doubles(dir / "back_odo.bin", {0.0, 1.0, 0.5, 1.0, 0.4, 1.0});
  EXPECT_HAS(read_all(dir / "back_odo.bin"), "back_odo.bin': record 2 (0-based), column 0 (t): time 0.4 goes back");
  write_doubles(dir / "rep_odo.bin", {0.0, 1.0, 0.0, 1.0});
  EXPECT_HAS(read_all(dir / "rep_odo.bin"), "record 1 (0-based), column 0 (t): time 0 repeats");
  write_doubles(dir / "trunc_odo.bin", {0.0, 1.0, 0.5});
  EXPECT_HAS(read_all(dir / "trunc_odo.bin"), "truncated");
  write_doubles(dir / "empty_odo.bin", {});
  EXPECT_HAS(read_all(dir / "empty_odo.bin"), "empty_odo.bin': contains no odometer records (empty file)");
  EXPECT_HAS(read_all(dir / "none_odo.bin"), "none_odo.bin': file not found");
  write_text(dir / "odo.txt", "0 1\n0.5 fast\n");
  EXPECT_HAS(read_all(dir / "odo.txt", FileLayout::kText),
             "odo.txt': record 1 (0-based, line 2), column 1 (speed): cannot read 'fast'");
  EXPECT_HAS(error_of([&] { OdoWriter w(dir / "nan_odo.bin"); }), "already exists");
}
