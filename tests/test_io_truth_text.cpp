// Truth as users have it: a GNSS track as CSV/text (columns by header name or index,
// repeated fixes collapsed, time scale), TUM files in ENU and NED, the 5-column writer, and
// the real car's GNSS.csv when the shared data are there.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "wheelins/eval/truth_quality.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/io/truth_text.hpp"
#include "wheelins/nav/types.hpp"

using namespace wheelins;
using iotest::error_of;
using iotest::ScratchDir;
using iotest::write_text;
namespace fs = std::filesystem;

namespace {

const earth::Geodetic kOrigin{32.7655 * kDeg, 35.0136 * kDeg, 450.0};

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// A GNSS log as the car's: one row every 0.01 s whose Timestamp counts tenths (0.1 per
// row), a 5 Hz fix repeated for 20 rows, driving north at 5 m/s from kOrigin. `fix_pos`
// may move a fix; `rows` rows in all.
struct GnssLog {
  int rows = 200;
  std::string header = "Timestamp,Lat_GNSS,Long_GNSS,Height_GNSS,Acc_X,Acc_Y";
  std::function<Vec3(int)> fix_pos = [](int k) { return Vec3(1.0 * k, 0.0, 0.0); };  // 5 m/s at 5 Hz
  std::string text() const {
    const earth::LocalFrame frame(kOrigin);
    std::string s = header + "\n";
    for (int i = 0; i < rows; ++i) {
      const int k = i / 20;
      const earth::Geodetic g = frame.geodetic_from_ned(fix_pos(k));
      s += fixed(0.1 * i, 1) + "," + fixed(g.lat / kDeg, 9) + "," + fixed(g.lon / kDeg, 9) + "," +
           fixed(g.h, 3) + ",0.01," + std::to_string(i % 7) + "\n";
    }
    return s;
  }
};

TruthReadOptions scaled(double scale) {
  TruthReadOptions o;
  o.time_scale = scale;
  return o;
}

}  // namespace

TEST(IoTruthText, GnssCsvRepeatedFixesCollapsedWithTimeScale) {
  ScratchDir dir;
  const auto file = dir / "GNSS.csv";
  write_text(file, GnssLog{}.text());
  EXPECT_EQ(detect_truth_layout(file), TruthLayout::kText);
  const TruthData d = read_truth(file, TruthLayout::kAuto, scaled(0.1));
  EXPECT_EQ(d.layout, TruthLayout::kText);
  EXPECT_FALSE(d.has_velocity);
  EXPECT_FALSE(d.has_attitude);
  EXPECT_EQ(d.rows, 200u);
  EXPECT_EQ(d.collapsed, 190u);
  ASSERT_EQ(d.records.size(), 10u);
  const earth::LocalFrame frame(kOrigin);
  for (std::size_t k = 0; k < d.records.size(); ++k) {
    EXPECT_NEAR(d.records[k].t, 0.2 * static_cast<double>(k), 1e-12) << k;  // the first row's time
    const Vec3 p = frame.ned_from_geodetic(d.records[k].lla);
    EXPECT_NEAR(p.x(), 1.0 * static_cast<double>(k), 1e-3) << k;  // 1e-9 deg is 0.1 mm
    EXPECT_NEAR(p.y(), 0.0, 1e-3) << k;
  }
  EXPECT_HAS(d.description, "time 'Timestamp' (0) x 0.1");
  EXPECT_HAS(d.description, "lat 'Lat_GNSS' (1)");
  EXPECT_HAS(d.description, "lon 'Long_GNSS' (2)");
  EXPECT_HAS(d.description, "h 'Height_GNSS' (3)");
  EXPECT_HAS(d.description, "190 repeating");

  // Without collapsing every row is a record (0.01 s apart after scaling).
  TruthReadOptions keep = scaled(0.1);
  keep.collapse_repeated = false;
  const TruthData all = read_truth(file, TruthLayout::kText, keep);
  ASSERT_EQ(all.records.size(), 200u);
  EXPECT_NEAR(all.records[37].t, 0.37, 1e-12);
  EXPECT_EQ(all.collapsed, 0u);

  // The time offset is added after scaling; the streaming reader gives the same records.
  TruthReadOptions off = scaled(0.1);
  off.time_offset = 1000.0;
  TruthReader rd(file, TruthLayout::kAuto, off);
  TruthRecord r;
  std::size_t n = 0;
  while (rd.next(r)) {
    EXPECT_NEAR(r.t, 1000.0 + 0.2 * static_cast<double>(n), 1e-9);
    EXPECT_EQ(r.lla.lat, d.records[n].lla.lat);
    ++n;
  }
  EXPECT_EQ(n, 10u);
  EXPECT_EQ(rd.collapsed(), 190u);
  EXPECT_FALSE(rd.has_attitude());
}

TEST(IoTruthText, ColumnsByNameIndexDelimiterAndNoHeader) {
  ScratchDir dir;
  // Semicolons, units in brackets, other column order, quoted names.
  const auto semi = dir / "track.txt";
  write_text(semi, "# exported track\n\"height [m]\";\"Latitude [deg]\";\"Longitude [deg]\";time [s]\n"
                   "20;30.5;114.3;10\n20.5;30.50001;114.3;11\n");
  const TruthData a = read_truth(semi);
  ASSERT_EQ(a.records.size(), 2u);
  EXPECT_EQ(a.records[1].t, 11.0);
  EXPECT_EQ(a.records[1].lla.h, 20.5);
  EXPECT_NEAR(a.records[1].lla.lat, 30.50001 * kDeg, 1e-15);

  // Blank-separated without a header: columns as 0-based indices.
  const auto bare = dir / "bare.txt";
  write_text(bare, "1 99 30.5 114.3 20\n2 99 30.50001 114.3 20\n");
  EXPECT_HAS(error_of([&] { detect_truth_layout(bare); }), "bare.txt");
  TruthReadOptions o;
  set_truth_columns(o, "0,2,3,4");
  const TruthData b = read_truth(bare, TruthLayout::kText, o);
  ASSERT_EQ(b.records.size(), 2u);
  EXPECT_EQ(b.records[0].t, 1.0);
  EXPECT_NEAR(b.records[1].lla.lat, 30.50001 * kDeg, 1e-15);
  EXPECT_HAS(error_of([&] { read_truth(bare, TruthLayout::kText); }), "0-based index");

  // Names given explicitly pick among look-alikes; an ambiguous header is refused.
  const auto two = dir / "two.csv";
  write_text(two, "t,lat,lat_std,lon,h\n1,30.5,0.1,114.3,20\n2,30.50001,0.1,114.3,20\n");
  const std::string amb = error_of([&] { read_truth(two); });
  EXPECT_HAS(amb, "two.csv");
  EXPECT_HAS(amb, "'lat' (1), 'lat_std' (2)");
  TruthReadOptions named;
  set_truth_columns(named, "t,LAT,lon,h");
  EXPECT_EQ(read_truth(two, TruthLayout::kText, named).records.size(), 2u);
  set_truth_columns(named, "t,latitude,lon,h");
  EXPECT_HAS(error_of([&] { read_truth(two, TruthLayout::kText, named); }), "no column 'latitude'");
  EXPECT_HAS(error_of([&] { set_truth_columns(named, "t,lat,lon"); }), "expected 4 columns");
  const auto noh = dir / "noh.csv";
  write_text(noh, "time,lat,lon,speed\n1,30.5,114.3,2\n");
  EXPECT_HAS(error_of([&] { read_truth(noh); }), "no column looks like the height");
}

TEST(IoTruthText, RejectsBadRowsNamingFileRecordLineAndColumn) {
  ScratchDir dir;
  auto with_row = [&](const std::string& name, int at, const std::string& row) {
    GnssLog log;
    log.rows = 60;
    std::string text = log.text();
    // Replace data row `at` (0-based; line at + 2).
    std::size_t pos = text.find('\n') + 1;
    for (int i = 0; i < at; ++i) pos = text.find('\n', pos) + 1;
    const std::size_t end = text.find('\n', pos);
    text.replace(pos, end - pos, row);
    write_text(dir / name, text);
    return dir / name;
  };
  // A new fix whose time goes back.
  const auto back = with_row("back.csv", 40, "1.5,32.7656,35.0136,450.0,0,0");
  const std::string m1 = error_of([&] { read_truth(back, TruthLayout::kAuto, scaled(0.1)); });
  EXPECT_HAS(m1, "back.csv");
  EXPECT_HAS(m1, "record 40 (0-based, line 42)");
  EXPECT_HAS(m1, "column 0 (Timestamp)");
  EXPECT_HAS(m1, "does not increase");
  // NaN and text.
  const auto nan = with_row("nan.csv", 5, "0.5,nan,35.0136,450.0,0,0");
  const std::string m2 = error_of([&] { read_truth(nan); });
  EXPECT_HAS(m2, "nan.csv': record 5 (0-based, line 7), column 1 (Lat_GNSS)");
  EXPECT_HAS(m2, "finite");
  const auto word = with_row("word.csv", 7, "0.7,32.7,35.0136,high,0,0");
  EXPECT_HAS(error_of([&] { read_truth(word); }), "column 3 (Height_GNSS): not a number: 'high'");
  // Latitude out of range.
  const auto lat = with_row("lat.csv", 3, "0.3,95.5,35.0136,450.0,0,0");
  const std::string m3 = error_of([&] { read_truth(lat); });
  EXPECT_HAS(m3, "record 3 (0-based, line 5), column 1 (Lat_GNSS)");
  EXPECT_HAS(m3, "out of range");
  // Too few fields.
  const auto short_row = with_row("short.csv", 2, "0.2,32.7");
  EXPECT_HAS(error_of([&] { read_truth(short_row); }), "record 2 (0-based, line 4): 2 fields");
  // A header and nothing else; a file of comments only.
  write_text(dir / "empty.csv", "Timestamp,Lat_GNSS,Long_GNSS,Height_GNSS\n");
  EXPECT_HAS(error_of([&] { read_truth(dir / "empty.csv"); }), "empty truth file");
  write_text(dir / "comments.csv", "# nothing\n\n");
  EXPECT_HAS(error_of([&] { read_truth(dir / "comments.csv"); }), "no data");
  // Repeated rows whose time does not advance are merged, not an error; kept, they are.
  const auto same = dir / "same.csv";
  write_text(same, "t,lat,lon,h\n1,30.5,114.3,20\n1,30.5,114.3,20\n2,30.50001,114.3,20\n");
  EXPECT_EQ(read_truth(same).records.size(), 2u);
  TruthReadOptions keep;
  keep.collapse_repeated = false;
  EXPECT_HAS(error_of([&] { read_truth(same, TruthLayout::kText, keep); }), "record 1 (0-based, line 3)");
  // A bad time scale.
  EXPECT_HAS(error_of([&] { read_truth(same, TruthLayout::kAuto, scaled(0.0)); }), "time scale");
}

TEST(IoTruthText, BinaryDetectionUnchangedBesideText) {
  ScratchDir dir;
  std::vector<TruthRecord> recs;
  for (int i = 0; i < 10; ++i) {
    TruthRecord r;
    r.t = 100.0 + i;
    r.lla = {30.5 * kDeg, 114.3 * kDeg + 1e-7 * i, 20.0};
    recs.push_back(r);
  }
  write_truth(dir / "g11.bin", recs);
  write_truth(dir / "p5.bin", recs, TruthLayout::kPos5);
  EXPECT_EQ(detect_truth_layout(dir / "g11.bin"), TruthLayout::kGins11);
  EXPECT_EQ(detect_truth_layout(dir / "p5.bin"), TruthLayout::kPos5);
  write_text(dir / "odd.bin", std::string(17, 'x'));  // text-like but no line: still binary's verdict
  EXPECT_HAS(error_of([&] { detect_truth_layout(dir / "odd.bin"); }), "fits neither");
  EXPECT_EQ(truth_layout_from_name("text"), TruthLayout::kText);
  EXPECT_EQ(truth_layout_from_name("tum"), TruthLayout::kTum);
  EXPECT_STREQ(truth_layout_name(TruthLayout::kText), "text");
}

TEST(IoTruthText, Pos5WriterRoundTrip) {
  ScratchDir dir;
  // A GNSS track converted to the 5-column binary and read back.
  write_text(dir / "GNSS.csv", GnssLog{}.text());
  const TruthData track = read_truth(dir / "GNSS.csv", TruthLayout::kAuto, scaled(0.1));
  const auto bin = dir / "GINS-body.bin";
  write_truth(bin, track.records, TruthLayout::kPos5);
  EXPECT_EQ(fs::file_size(bin), track.records.size() * 40u);
  EXPECT_FALSE(iotest::partial_left(bin));
  const TruthData back = read_truth(bin);
  EXPECT_EQ(back.layout, TruthLayout::kPos5);
  EXPECT_FALSE(back.has_velocity || back.has_attitude);
  ASSERT_EQ(back.records.size(), track.records.size());
  for (std::size_t i = 0; i < back.records.size(); ++i) {
    EXPECT_EQ(back.records[i].t, track.records[i].t);
    EXPECT_NEAR(back.records[i].lla.lat, track.records[i].lla.lat, 1e-15);
    EXPECT_NEAR(back.records[i].lla.lon, track.records[i].lla.lon, 1e-15);
    EXPECT_EQ(back.records[i].lla.h, track.records[i].lla.h);
  }
  {  // The fifth column is 0.
    BinaryRowReader rows(bin, 5);
    const double* r = rows.next();
    ASSERT_NE(r, nullptr);
    EXPECT_EQ(r[4], 0.0);
  }
  // The streaming writer validates as the 11-column one does.
  {
    TruthWriter w(dir / "w.bin", TruthLayout::kPos5);
    w.write(track.records[1]);
    EXPECT_HAS(error_of([&] { w.write(track.records[0]); }), "record 1");
    TruthRecord bad = track.records[2];
    bad.lla.h = std::nan("");
    EXPECT_HAS(error_of([&] { w.write(bad); }), "non-finite");
  }
  EXPECT_FALSE(fs::exists(dir / "w.bin"));
  EXPECT_HAS(error_of([&] { write_truth(bin, track.records, TruthLayout::kPos5); }), "already exists");
  EXPECT_HAS(error_of([&] { TruthWriter w(dir / "x.bin", TruthLayout::kText); }), "gins11 or pos5");
}

// A curved drive with roll and pitch written as TUM in NED (x north, y east, z down; q = C_v^n,
// body FRD) and in ENU (x east, y north, z up; body FLU): both read to the same records.
TEST(IoTruthText, TumEnuAndNedReadToTheSameRecords) {
  ScratchDir dir;
  const earth::LocalFrame frame(kOrigin);
  Mat3 enu_from_ned;
  enu_from_ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Mat3 flu_from_frd = Vec3(1, -1, -1).asDiagonal();
  std::string ned = "# t x y z qx qy qz qw\n", enu = ned;
  std::vector<Vec3> p_true, rpy_true;
  for (int i = 0; i < 50; ++i) {
    const double t = 0.1 * i;
    const Vec3 p(20.0 * std::sin(0.2 * t), 20.0 * (1.0 - std::cos(0.2 * t)), -0.3 * t);
    const Vec3 rpy(0.05 * std::sin(t), -0.03 + 0.01 * t, wrap_pi(0.2 * t + 3.0));
    p_true.push_back(p);
    rpy_true.push_back(rpy);
    const Mat3 C = dcm_from_euler(rpy);
    auto line = [&](const Vec3& x, const Quat& q) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "%.3f %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", t, x.x(), x.y(), x.z(),
                    q.x(), q.y(), q.z(), q.w());
      return std::string(buf);
    };
    ned += line(p, Quat(C));
    enu += line(enu_from_ned * p, Quat(Mat3(enu_from_ned * C * flu_from_frd)));
  }
  write_text(dir / "ned.tum", ned);
  write_text(dir / "enu.txt", enu);
  EXPECT_EQ(detect_truth_layout(dir / "enu.txt"), TruthLayout::kTum);
  TruthReadOptions o;
  o.tum_origin = kOrigin;
  EXPECT_HAS(error_of([&] { read_truth(dir / "enu.txt"); }), "origin");
  const TruthData e = read_truth(dir / "enu.txt", TruthLayout::kAuto, o);  // ENU is the default
  o.tum_frame = TumFrame::kNed;
  const TruthData n = read_truth(dir / "ned.tum", TruthLayout::kTum, o);
  EXPECT_EQ(e.layout, TruthLayout::kTum);
  EXPECT_TRUE(e.has_attitude);
  EXPECT_FALSE(e.has_velocity);
  EXPECT_HAS(e.description, "ENU");
  ASSERT_EQ(e.records.size(), 50u);
  ASSERT_EQ(n.records.size(), 50u);
  for (std::size_t i = 0; i < 50; ++i) {
    EXPECT_EQ(e.records[i].t, n.records[i].t);
    EXPECT_NEAR((frame.ned_from_geodetic(e.records[i].lla) - p_true[i]).norm(), 0.0, 1e-6) << i;
    EXPECT_NEAR((frame.ned_from_geodetic(n.records[i].lla) - p_true[i]).norm(), 0.0, 1e-6) << i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(wrap_pi(e.records[i].rpy[k] - rpy_true[i][k]), 0.0, 1e-9) << i << " " << k;
      EXPECT_NEAR(wrap_pi(n.records[i].rpy[k] - rpy_true[i][k]), 0.0, 1e-9) << i << " " << k;
    }
  }
}

// The ENU convention checked by hand, independently of the conversion formula: facing east
// (identity) is heading 90 deg; the nose turned down about the left axis is negative pitch.
TEST(IoTruthText, TumEnuConventionByHand) {
  ScratchDir dir;
  const double s10 = std::sin(5.0 * kDeg), c10 = std::cos(5.0 * kDeg);  // half of 10 deg
  write_text(dir / "a.tum", "0 10 20 3 0 0 0 1\n1 10 20 3 0 " + fixed(s10, 12) + " 0 " + fixed(c10, 12) +
                                "\n2 10 20 3 0 0 0.7071067811865476 0.7071067811865476\n");
  TruthReadOptions o;
  o.tum_origin = kOrigin;
  const TruthData d = read_truth(dir / "a.tum", TruthLayout::kAuto, o);
  ASSERT_EQ(d.records.size(), 3u);
  const earth::LocalFrame frame(kOrigin);
  const Vec3 p = frame.ned_from_geodetic(d.records[0].lla);
  EXPECT_NEAR(p.x(), 20.0, 1e-6);  // north = y
  EXPECT_NEAR(p.y(), 10.0, 1e-6);  // east = x
  EXPECT_NEAR(p.z(), -3.0, 1e-6);  // down = -up
  EXPECT_NEAR(d.records[0].rpy.z(), 90.0 * kDeg, 1e-12);
  EXPECT_NEAR(d.records[0].rpy.x(), 0.0, 1e-12);
  EXPECT_NEAR(d.records[1].rpy.y(), -10.0 * kDeg, 1e-9);
  EXPECT_NEAR(d.records[1].rpy.z(), 90.0 * kDeg, 1e-9);
  EXPECT_NEAR(d.records[2].rpy.z(), 0.0, 1e-9);  // turned 90 deg to the left of east: north
  // The same numbers read as NED: identity faces north.
  o.tum_frame = TumFrame::kNed;
  EXPECT_NEAR(read_truth(dir / "a.tum", TruthLayout::kTum, o).records[0].rpy.z(), 0.0, 1e-12);
  // Bad rows.
  write_text(dir / "b.tum", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 2\n");
  EXPECT_HAS(error_of([&] { read_truth(dir / "b.tum", TruthLayout::kTum, o); }), "record 1 (0-based, line 2)");
  write_text(dir / "c.tum", "0 0 0 0 0 0 0 1\n0 0 0 0 0 0 0 1\n");
  EXPECT_HAS(error_of([&] { read_truth(dir / "c.tum", TruthLayout::kTum, o); }), "does not increase");
  write_text(dir / "d.tum", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n");
  EXPECT_HAS(error_of([&] { read_truth(dir / "d.tum", TruthLayout::kTum, o); }), "7 values, expected 8");
  EXPECT_EQ(tum_frame_from_name("ned"), TumFrame::kNed);
  EXPECT_HAS(error_of([&] { tum_frame_from_name("nwu"); }), "nwu");
}

// The real car's GNSS log (public "Wheel-Mounted Inertial" dataset, trial 2), read from the
// shared data when WHEELINS_SHARED_DIR points there: its Timestamp counts tenths of a second,
// so with a time scale of 0.1 it is a 5 Hz track of about 133 s and 527 m.
TEST(IoTruthText, RealCarGnssCsv) {
  const char* env = std::getenv("WHEELINS_SHARED_DIR");
  if (!env) GTEST_SKIP() << "WHEELINS_SHARED_DIR is not set";
  const fs::path file = fs::path(env) / "data" / "wmi-car" / "trial02" / "GNSS.csv";
  if (!fs::exists(file)) GTEST_SKIP() << file << " is not there";
  EXPECT_EQ(detect_truth_layout(file), TruthLayout::kText);
  const TruthData d = read_truth(file, TruthLayout::kAuto, scaled(0.1));
  EXPECT_EQ(d.rows, 13372u);
  // 13372 rows / 20 is 669 fixes, but the receiver sometimes reports the same position for
  // two to four fixes in a row (0.4 - 0.8 s between changes): those are one fix, 634 remain.
  EXPECT_GE(d.records.size(), 620u);
  EXPECT_LE(d.records.size(), 680u);
  const double duration = d.records.back().t - d.records.front().t;
  EXPECT_NEAR(duration, 132.64, 0.1);
  EXPECT_NEAR(static_cast<double>(d.records.size()) / duration, 4.8, 0.2);  // ~5 Hz
  const earth::LocalFrame frame(d.records.front().lla);
  double path = 0.0;
  for (std::size_t i = 1; i < d.records.size(); ++i)
    path += (frame.ned_from_geodetic(d.records[i].lla) - frame.ned_from_geodetic(d.records[i - 1].lla))
                .head<2>()
                .norm();
  EXPECT_NEAR(path, 527.0, 3.0);
  const eval::TruthQualityReport q = eval::check_truth_quality(d);
  EXPECT_NEAR(q.median_interval, 0.2, 0.011);
  EXPECT_EQ(q.gap_count, 0u);
  EXPECT_EQ(q.jump_count, 0u);
  EXPECT_EQ(q.repeated, 0u);  // collapsed on read
  // Read raw (every row a record, 0.01 s apart), the repeats show as stalls.
  TruthReadOptions raw = scaled(0.1);
  raw.collapse_repeated = false;
  const eval::TruthQualityReport qr = eval::check_truth_quality(read_truth(file, TruthLayout::kText, raw));
  EXPECT_EQ(qr.records, 13372u);
  EXPECT_EQ(qr.repeated, 13372u - d.records.size());
  EXPECT_GT(qr.stall_count, 600u);
  EXPECT_EQ(qr.jump_count, 0u);
}
