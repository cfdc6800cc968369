// Truth (GINS.bin) and trajectory file formats: round trips, layout detection,
// validation messages and overwrite refusal.
#include <gtest/gtest.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/odometer.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/nav/types.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

// A fresh directory per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("wheelins_iotest_" + std::to_string(::getpid()) + "_" + info->test_suite_name() +
             "_" + info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

void write_rows(const fs::path& file, int ncols, const std::vector<std::vector<double>>& rows) {
  BinaryRowWriter w(file, ncols);
  for (const auto& r : rows) w.write(r.data());
  w.commit();
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void spit(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
}

// Expects `fn` to throw InputError whose message contains every fragment.
template <typename Fn>
void expect_input_error(Fn&& fn, std::initializer_list<std::string> fragments) {
  try {
    fn();
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& f : fragments)
      EXPECT_NE(msg.find(f), std::string::npos) << "message '" << msg << "' lacks '" << f << "'";
  }
}

std::vector<TruthRecord> sample_truth(int n) {
  std::vector<TruthRecord> out;
  for (int i = 0; i < n; ++i) {
    TruthRecord r;
    r.t = 132030.005 + 0.005 * i;
    r.lla = {30.5278 * kDeg + 1e-7 * i, 114.3556 * kDeg - 2e-7 * i, 20.0 + 0.01 * i};
    r.v_ned = Vec3(1.0 + 0.1 * i, -0.5, 0.01 * i);
    r.rpy = Vec3(0.01 * i, -0.02, wrap_pi(3.0 + 0.1 * i));
    out.push_back(r);
  }
  return out;
}

TrajectoryRecord sample_traj_record(int i) {
  TrajectoryRecord r;
  r.t = 1000.0 + 0.1 * i + 1.0 / 3.0;
  r.p_inN = Vec3(1.0 / 7.0 + i, -2.5 * i, 0.001 * i);
  r.lla = {30.5 * kDeg + 1e-8 * i, 114.3 * kDeg + 3e-8 * i, 15.0 + 0.1 / 3.0};
  r.v_inN = Vec3(1.1, -0.3, 0.05 * i);
  r.rpy = Vec3(0.02, -0.03, wrap_pi(0.4 * i));
  r.p_std = Vec3(0.1 * i, 0.2, 0.3);
  r.v_std = Vec3(0.01, 0.02, 0.03);
  r.rpy_std = Vec3(0.001, 0.002, 0.003);
  r.bg = Vec3(10, -20, 30) * kDeg / 3600.0;
  r.ba = Vec3(0.01, -0.02, 0.03);
  r.sg = Vec3(100e-6, -200e-6, 300e-6);
  r.sa = Vec3(-1e-3, 2e-3, 3e-3);
  r.bg_std = Vec3(1, 2, 3) * kDeg / 3600.0;
  r.ba_std = Vec3(1e-3, 2e-3, 3e-3);
  r.sg_std = Vec3(1e-5, 2e-5, 3e-5);
  r.sa_std = Vec3(4e-5, 5e-5, 6e-5);
  return r;
}

void expect_vec_near(const Vec3& a, const Vec3& b, double tol, const char* what) {
  EXPECT_NEAR((a - b).norm(), 0.0, tol) << what << ": " << a.transpose() << " vs "
                                        << b.transpose();
}

// 9 significant digits: relative rounding error at most 0.5e-8.
void expect_vec_rel(const Vec3& a, const Vec3& b, const char* what) {
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(a[i], b[i], 5e-9 * std::abs(b[i]) + 1e-300) << what << "[" << i << "]";
}

}  // namespace

// ----------------------------------------------------------------- truth files

TEST(IoTruth, WriterRoundTripIsExact) {
  TempDir dir;
  const auto file = dir / "GINS.bin";
  const auto recs = sample_truth(50);
  write_truth(file, recs, false, 2100);
  EXPECT_EQ(fs::file_size(file), 50u * 88u);
  EXPECT_FALSE(iotest::partial_left(file));
  const TruthData d = read_truth(file);
  EXPECT_EQ(d.layout, TruthLayout::kGins11);
  EXPECT_TRUE(d.has_velocity_attitude());
  EXPECT_EQ(d.gps_week, 2100.0);
  ASSERT_EQ(d.records.size(), recs.size());
  for (std::size_t i = 0; i < recs.size(); ++i) {
    EXPECT_EQ(d.records[i].t, recs[i].t);
    EXPECT_NEAR(d.records[i].lla.lat, recs[i].lla.lat, 1e-15);
    EXPECT_NEAR(d.records[i].lla.lon, recs[i].lla.lon, 1e-15);
    EXPECT_EQ(d.records[i].lla.h, recs[i].lla.h);
    EXPECT_EQ(d.records[i].v_ned, recs[i].v_ned);
    expect_vec_near(d.records[i].rpy, recs[i].rpy, 1e-14, "rpy");
  }
}

TEST(IoTruth, StreamingWriterValidatesAndCommits) {
  TempDir dir;
  const auto file = dir / "truth.bin";
  {
    TruthWriter w(file);
    const auto recs = sample_truth(3);
    w.write(recs[0]);
    w.write(recs[1]);
    EXPECT_EQ(w.rows(), 2u);
    expect_input_error([&] { w.write(recs[0]); }, {"truth.bin", "record 2", "does not increase"});
    TruthRecord bad = recs[2];
    bad.v_ned.x() = std::nan("");
    expect_input_error([&] { w.write(bad); }, {"record 2", "non-finite"});
    // Destroyed without commit: nothing appears.
  }
  EXPECT_FALSE(fs::exists(file));
  EXPECT_FALSE(iotest::partial_left(file));
}

TEST(IoTruth, FiveColumnLayout) {
  TempDir dir;
  const auto file = dir / "GINS-body.bin";
  write_rows(file, 5, {{10.0, 30.1, 114.2, 20.0, 0.0}, {10.5, 30.1000001, 114.2, 20.1, 0.0},
                       {11.0, 30.1000002, 114.2000001, 20.2, 7.0}});
  const TruthData d = read_truth(file);
  EXPECT_EQ(d.layout, TruthLayout::kPos5);
  EXPECT_FALSE(d.has_velocity_attitude());
  EXPECT_FALSE(d.has_velocity);
  EXPECT_FALSE(d.has_attitude);
  ASSERT_EQ(d.records.size(), 3u);
  EXPECT_EQ(d.records[1].t, 10.5);
  EXPECT_NEAR(d.records[1].lla.lat, 30.1000001 * kDeg, 1e-15);
  EXPECT_NEAR(d.records[2].lla.lon, 114.2000001 * kDeg, 1e-15);
  EXPECT_EQ(d.records[2].lla.h, 20.2);
}

TEST(IoTruth, AmbiguousSizeDecidedByContent) {
  TempDir dir;
  // 440 bytes: 5 rows of 11 or 11 rows of 5.
  const auto f11 = dir / "a11.bin";
  std::vector<std::vector<double>> rows11;
  for (int i = 0; i < 5; ++i)
    rows11.push_back({2200, 5000.0 + i, 30.0 + 1e-6 * i, 114.0, 20, 0.5, 0.1, 0, 1, 2, 45.0});
  write_rows(f11, 11, rows11);
  EXPECT_EQ(detect_truth_layout(f11), TruthLayout::kGins11);
  EXPECT_EQ(read_truth(f11).records.size(), 5u);

  const auto f5 = dir / "a5.bin";
  std::vector<std::vector<double>> rows5;
  for (int i = 0; i < 11; ++i) rows5.push_back({5000.0 + i, 30.0 + 1e-6 * i, 114.0, 20, 0});
  write_rows(f5, 5, rows5);
  EXPECT_EQ(detect_truth_layout(f5), TruthLayout::kPos5);
  EXPECT_EQ(read_truth(f5).records.size(), 11u);

  // Static 11-column data (constant velocity/attitude columns) is still recognised.
  const auto fs11 = dir / "static11.bin";
  std::vector<std::vector<double>> stat;
  for (int i = 0; i < 40; ++i) stat.push_back({2200, 100.0 + i, 30, 114, 20, 0, 0, 0, 0, 0, 0});
  write_rows(fs11, 11, stat);
  EXPECT_EQ(detect_truth_layout(fs11), TruthLayout::kGins11);

  // Explicit layout overrides detection (and then validation speaks).
  expect_input_error([&] { read_truth(f5, TruthLayout::kGins11); }, {"a5.bin", "record"});
}

TEST(IoTruth, RejectsBadInputNamingFileAndRecord) {
  TempDir dir;
  const auto nan_file = dir / "nan.bin";
  write_rows(nan_file, 11, {{2200, 1, 30, 114, 0, 0, 0, 0, 0, 0, 0},
                            {2200, 2, 30, 114, std::nan(""), 0, 0, 0, 0, 0, 0}});
  expect_input_error([&] { read_truth(nan_file, TruthLayout::kGins11); },
                     {"nan.bin", "record 1", "column 4 (h)", "finite"});

  const auto time_file = dir / "time.bin";
  write_rows(time_file, 11, {{2200, 1, 30, 114, 0, 0, 0, 0, 0, 0, 0},
                             {2200, 2, 30, 114, 0, 0, 0, 0, 0, 0, 0},
                             {2200, 2, 30, 114, 0, 0, 0, 0, 0, 0, 0}});
  expect_input_error([&] { read_truth(time_file, TruthLayout::kGins11); },
                     {"time.bin", "record 2", "does not increase"});

  const auto lat_file = dir / "lat.bin";
  write_rows(lat_file, 5, {{1, 30, 114, 0, 0}, {2, 95, 114, 0, 0}});
  expect_input_error([&] { read_truth(lat_file, TruthLayout::kPos5); },
                     {"lat.bin", "record 1", "out of range"});

  const auto lon_file = dir / "lon.bin";
  write_rows(lon_file, 5, {{1, 30, 181, 0, 0}});
  expect_input_error([&] { read_truth(lon_file, TruthLayout::kPos5); },
                     {"lon.bin", "record 0", "out of range"});

  // An 11-column file cut to a whole number of 40-byte rows: named as truncated, not read
  // as 5-column rows with a "latitude" of 2200.
  const auto cut = dir / "cut.bin";
  std::vector<std::vector<double>> rows;
  for (int i = 0; i < 100; ++i) rows.push_back({2200, 100.0 + i, 30, 114, 20, 0, 0, 0, 0, 0, 0});
  write_rows(cut, 11, rows);
  std::filesystem::resize_file(cut, 8760);  // 8760 = 219 x 40, not a multiple of 88
  expect_input_error([&] { read_truth(cut); }, {"cut.bin", "8760", "truncated or misaligned"});

  const auto odd = dir / "odd.bin";
  spit(odd, std::string(17, 'x'));
  expect_input_error([&] { read_truth(odd); }, {"odd.bin", "fits neither"});

  const auto empty = dir / "empty.bin";
  spit(empty, "");
  expect_input_error([&] { read_truth(empty); }, {"empty.bin", "empty"});

  expect_input_error([&] { read_truth(dir / "missing.bin"); }, {"missing.bin", "not found"});

  // 440 bytes of garbage fits both layouts and is valid in neither.
  const auto junk = dir / "junk.bin";
  std::vector<std::vector<double>> jr(5, std::vector<double>(11, -1.5));
  write_rows(junk, 11, jr);
  expect_input_error([&] { read_truth(junk); }, {"junk.bin", "fits both", "explicitly"});
}

TEST(IoTruth, WeekRolloverKeepsTimeContinuous) {
  TempDir dir;
  const auto file = dir / "roll.bin";
  write_rows(file, 11, {{2200, 604799.5, 30, 114, 0, 0, 0, 0, 0, 0, 0},
                        {2201, 0.0, 30, 114, 0, 0, 0, 0, 0, 0, 0}});
  const auto d = read_truth(file);
  ASSERT_EQ(d.records.size(), 2u);
  EXPECT_DOUBLE_EQ(d.records[1].t - d.records[0].t, 0.5);
}

TEST(IoTruth, OverwriteRefusedUnlessAsked) {
  TempDir dir;
  const auto file = dir / "GINS.bin";
  spit(file, "precious");
  expect_input_error([&] { TruthWriter w(file); }, {"GINS.bin", "already exists"});
  EXPECT_EQ(slurp(file), "precious");
  write_truth(file, sample_truth(2), /*overwrite=*/true);
  EXPECT_EQ(read_truth(file).records.size(), 2u);
}

// ----------------------------------------------------------- trajectory files

TEST(IoTraj, CsvRoundTrip) {
  TempDir dir;
  const auto file = dir / "traj.csv";
  std::vector<TrajectoryRecord> recs;
  for (int i = 0; i < 20; ++i) recs.push_back(sample_traj_record(i));
  {
    auto w = make_trajectory_writer(TrajectoryFormat::kCsv, file);
    for (const auto& r : recs) w->write(r);
    EXPECT_EQ(w->records(), 20u);
    EXPECT_FALSE(fs::exists(file));  // only the partial file until commit
    w->commit();
  }
  const std::string text = slurp(file);
  EXPECT_EQ(text.rfind("t_s,north_m,east_m,down_m,lat_deg,lon_deg,h_m,vn_m_s,ve_m_s,vd_m_s,"
                       "roll_deg,pitch_deg,heading_deg,north_std_m",
                       0),
            0u);
  EXPECT_NE(text.find("bg_x_deg_h"), std::string::npos);
  EXPECT_NE(text.find("sa_z_std_ppm"), std::string::npos);

  const TrajectoryData d = read_trajectory(file);
  EXPECT_EQ(d.format, TrajectoryFormat::kCsv);
  EXPECT_TRUE(d.has_lla && d.has_ned && d.has_velocity && d.has_heading && d.has_roll_pitch &&
              d.has_pos_std);
  ASSERT_EQ(d.records.size(), recs.size());
  for (std::size_t i = 0; i < recs.size(); ++i) {
    const auto &a = d.records[i], &b = recs[i];
    EXPECT_EQ(a.t, b.t);            // shortest round-trip text: exact
    EXPECT_EQ(a.p_inN, b.p_inN);    // exact
    EXPECT_EQ(a.lla.h, b.lla.h);
    EXPECT_EQ(a.v_inN, b.v_inN);
    // Degrees <-> radians costs at most an ulp or two.
    EXPECT_NEAR(a.lla.lat, b.lla.lat, 1e-15);
    EXPECT_NEAR(a.lla.lon, b.lla.lon, 1e-15);
    expect_vec_near(a.rpy, b.rpy, 1e-15, "rpy");
    expect_vec_rel(a.p_std, b.p_std, "p_std");
    expect_vec_rel(a.rpy_std, b.rpy_std, "rpy_std");
    expect_vec_rel(a.bg, b.bg, "bg");
    expect_vec_rel(a.ba, b.ba, "ba");
    expect_vec_rel(a.sg, b.sg, "sg");
    expect_vec_rel(a.sa, b.sa, "sa");
    expect_vec_rel(a.bg_std, b.bg_std, "bg_std");
    expect_vec_rel(a.ba_std, b.ba_std, "ba_std");
    expect_vec_rel(a.sg_std, b.sg_std, "sg_std");
    expect_vec_rel(a.sa_std, b.sa_std, "sa_std");
  }
}

TEST(IoTraj, CsvReaderFindsColumnsByName) {
  TempDir dir;
  const auto file = dir / "other.csv";
  spit(file,
       "# produced elsewhere\n"
       "heading_deg, extra, t_s, lat_deg, lon_deg, h_m\n"
       "359, 7, 1.5, 30.0, 114.0, 10\n"
       "1, 8, 2.5, 30.0001, 114.0, 11\n");
  const TrajectoryData d = read_trajectory(file);
  EXPECT_TRUE(d.has_lla);
  EXPECT_FALSE(d.has_ned);
  EXPECT_TRUE(d.has_heading);
  EXPECT_FALSE(d.has_pos_std);
  ASSERT_EQ(d.records.size(), 2u);
  EXPECT_EQ(d.records[1].t, 2.5);
  EXPECT_NEAR(d.records[0].rpy.z(), 359 * kDeg, 1e-15);
  EXPECT_NEAR(d.records[1].lla.lat, 30.0001 * kDeg, 1e-15);
}

// A UTF-8 byte-order mark (which editors write at the start of a file, invisible in any
// message) is taken at the start of every text reader's file: IMU, odometer, trajectory
// (TUM) and truth (TUM, text columns); in the middle of a file it is bad data as before.
TEST(IoText, EveryTextReaderTakesAByteOrderMark) {
  TempDir dir;
  const std::string bom = "\xEF\xBB\xBF";
  iotest::write_text(dir / "imu.txt", bom + "100000.005 0 0 0 0 0 9.8\n100000.010 0 0 0 0 0 9.8\n");
  ImuReadOptions o;
  o.layout = FileLayout::kText;
  o.rate_hz = 200.0;
  ImuFileReader imu(dir / "imu.txt", o);
  ImuSample s;
  int n = 0;
  while (imu.next(s)) ++n;
  EXPECT_EQ(n, 2);
  EXPECT_EQ(imu.row().t, 100000.010);

  iotest::write_text(dir / "odo.txt", bom + "100000.5 1.25\n100001.0 1.5\n");
  OdoReader odo(dir / "odo.txt", FileLayout::kText);
  EXPECT_EQ(odo.first_time(), 100000.5);

  iotest::write_text(dir / "traj.tum", bom + "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n");
  EXPECT_EQ(read_trajectory(dir / "traj.tum").records.size(), 2u);

  iotest::write_text(dir / "truth.tum", bom + "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n");
  TruthReadOptions tum;
  tum.tum_origin = earth::Geodetic{0.5, 2.0, 10.0};
  EXPECT_EQ(read_truth(dir / "truth.tum", TruthLayout::kAuto, tum).records.size(), 2u);
  iotest::write_text(dir / "gnss.csv", bom + "t,lat,lon,h\n1.0,30.5,114.3,20\n2.0,30.50001,114.3,20\n");
  EXPECT_EQ(read_truth(dir / "gnss.csv").records.size(), 2u);

  // Not at the start of the file: an unreadable number, as any other stray bytes.
  iotest::write_text(dir / "mid.txt", "100000.005 0 0 0 0 0 9.8\n" + bom + "100000.010 0 0 0 0 0 9.8\n");
  ImuFileReader mid(dir / "mid.txt", o);
  EXPECT_THROW(
      {
        while (mid.next(s)) {
        }
      },
      InputError);
}

TEST(IoTraj, TumRoundTrip) {
  TempDir dir;
  const auto file = dir / "traj.tum";
  std::vector<TrajectoryRecord> recs;
  for (int i = 0; i < 30; ++i) recs.push_back(sample_traj_record(i));
  auto w = make_trajectory_writer(TrajectoryFormat::kTum, file);
  for (const auto& r : recs) w->write(r);
  w->commit();
  const TrajectoryData d = read_trajectory(file);
  EXPECT_EQ(d.format, TrajectoryFormat::kTum);
  EXPECT_TRUE(d.has_ned && d.has_heading && d.has_roll_pitch);
  EXPECT_FALSE(d.has_lla);
  ASSERT_EQ(d.records.size(), recs.size());
  for (std::size_t i = 0; i < recs.size(); ++i) {
    EXPECT_EQ(d.records[i].t, recs[i].t);
    EXPECT_EQ(d.records[i].p_inN, recs[i].p_inN);
    EXPECT_NEAR(d.records[i].rpy.x(), recs[i].rpy.x(), 1e-12);
    EXPECT_NEAR(d.records[i].rpy.y(), recs[i].rpy.y(), 1e-12);
    EXPECT_NEAR(wrap_pi(d.records[i].rpy.z() - recs[i].rpy.z()), 0.0, 1e-12);
  }
  // The quaternion is the vehicle attitude: heading 90 deg -> rotation about z by 90 deg.
  const auto file2 = dir / "east.tum";
  TrajectoryRecord r;
  r.rpy = Vec3(0, 0, kPi / 2);
  auto w2 = make_trajectory_writer(TrajectoryFormat::kTum, file2);
  w2->write(r);
  w2->commit();
  std::string text = slurp(file2);
  std::string last = text.substr(text.rfind('\n', text.size() - 2) + 1);  // the record after the '#' lines
  std::istringstream ss(last);
  double t, x, y, z, qx, qy, qz, qw;
  ss >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  EXPECT_NEAR(qz, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(qw, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(std::abs(qx) + std::abs(qy), 0.0, 1e-15);
}

TEST(IoTraj, WheelInsTrajTxt) {
  TempDir dir;
  const auto file = dir / "traj.txt";
  // The layout Wheel-INS writes: "%-15.9lf " per value, 10 values.
  spit(file,
       "132030.010000000 0.000000000     0.000000000     0.000000000     0.000000000     "
       "0.000000000     0.000000000     10.000000000    -3.380000000    90.000000000    \n"
       "132030.015000000 0.001000000     0.002000000     -0.000100000    0.200000000     "
       "0.400000000     0.000000000     12.000000000    -3.380000000    1.000000000     \n");
  const TrajectoryData d = read_trajectory(file);
  EXPECT_EQ(d.format, TrajectoryFormat::kWheelInsTraj);
  EXPECT_TRUE(d.has_ned && d.has_heading && d.has_velocity);
  EXPECT_FALSE(d.has_lla || d.has_roll_pitch || d.has_pos_std);
  ASSERT_EQ(d.records.size(), 2u);
  EXPECT_EQ(d.records[1].t, 132030.015);
  expect_vec_near(d.records[1].p_inN, Vec3(0.001, 0.002, -0.0001), 1e-15, "pos");
  expect_vec_near(d.records[1].v_inN, Vec3(0.2, 0.4, 0.0), 1e-15, "vel");
  // Wheel-IMU yaw 90 deg -> vehicle heading 0; yaw 1 deg -> heading -89 deg.
  EXPECT_NEAR(d.records[0].rpy.z(), 0.0, 1e-15);
  EXPECT_NEAR(d.records[1].rpy.z(), -89.0 * kDeg, 1e-14);
}

TEST(IoTraj, KmlDecimatedAndSmall) {
  TempDir dir;
  const auto file = dir / "traj.kml";
  TrajectoryWriterOptions opt;
  opt.kml_min_interval = 0.5;
  auto w = make_trajectory_writer(TrajectoryFormat::kKml, file, opt);
  // 100 s at 200 Hz.
  for (int i = 0; i < 20000; ++i) {
    TrajectoryRecord r;
    r.t = 0.005 * i;
    r.lla = {30.0 * kDeg + 1e-9 * i, 114.0 * kDeg, 12.0};
    w->write(r);
  }
  w->commit();
  const std::string text = slurp(file);
  EXPECT_NE(text.find("<LineString>"), std::string::npos);
  const auto b = text.find("<coordinates>\n") + 14;
  const auto e = text.find("</coordinates>");
  std::istringstream ss(text.substr(b, e - b));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(ss, line)) lines.push_back(line);
  // One point per 0.5 s over [0, 99.995] plus the final point.
  EXPECT_EQ(lines.size(), 201u);
  EXPECT_EQ(lines.front(), "114.000000000,30.000000000,12.000");
  double lon, lat, h;
  char c1, c2;
  std::istringstream last(lines.back());
  last >> lon >> c1 >> lat >> c2 >> h;
  EXPECT_NEAR(lat, (30.0 * kDeg + 1e-9 * 19999) / kDeg, 1e-9);

  // The count cap holds whatever the run length.
  const auto file2 = dir / "capped.kml";
  opt.kml_max_points = 50;
  auto w2 = make_trajectory_writer(TrajectoryFormat::kKml, file2, opt);
  for (int i = 0; i < 20000; ++i) {
    TrajectoryRecord r;
    r.t = 0.005 * i;
    r.lla = {30.0 * kDeg, 114.0 * kDeg, 0.0};
    w2->write(r);
  }
  w2->commit();
  const std::string t2 = slurp(file2);
  const auto b2 = t2.find("<coordinates>\n") + 14;
  const auto n2 = std::count(t2.begin() + static_cast<long>(b2),
                             t2.begin() + static_cast<long>(t2.find("</coordinates>")), '\n');
  EXPECT_LE(n2, 50);
  EXPECT_GE(n2, 25);
}

TEST(IoTraj, OverwriteRefusedUnlessAsked) {
  TempDir dir;
  for (auto fmt : {TrajectoryFormat::kCsv, TrajectoryFormat::kTum, TrajectoryFormat::kKml}) {
    const auto file = dir / (std::string("out.") + trajectory_format_name(fmt));
    spit(file, "precious");
    expect_input_error([&] { make_trajectory_writer(fmt, file); },
                       {file.filename().string(), "already exists"});
    EXPECT_EQ(slurp(file), "precious");
    TrajectoryWriterOptions opt;
    opt.overwrite = true;
    auto w = make_trajectory_writer(fmt, file, opt);
    w->write(sample_traj_record(0));
    EXPECT_EQ(slurp(file), "precious");  // untouched until commit
    w->commit();
    EXPECT_NE(slurp(file), "precious");
  }
  // An uncommitted writer leaves nothing behind.
  const auto file = dir / "never.csv";
  {
    auto w = make_trajectory_writer(TrajectoryFormat::kCsv, file);
    w->write(sample_traj_record(0));
  }
  EXPECT_FALSE(fs::exists(file));
  EXPECT_FALSE(iotest::partial_left(file));
}

TEST(IoTraj, BadInputNamesFileAndLine) {
  TempDir dir;
  const auto f1 = dir / "bad1.csv";
  spit(f1, "t_s,north_m,east_m,down_m\n1,0,0,0\n2,0,x,0\n");
  expect_input_error([&] { read_trajectory(f1); }, {"bad1.csv", "line 3", "east_m", "'x'"});

  const auto f2 = dir / "bad2.csv";
  spit(f2, "t_s,north_m,east_m,down_m\n1,0,0,0\n1,0,0,0\n");
  expect_input_error([&] { read_trajectory(f2); }, {"bad2.csv", "line 3", "does not increase"});

  const auto f3 = dir / "bad3.csv";
  spit(f3, "t_s,north_m,east_m,down_m\n1,0,0\n");
  expect_input_error([&] { read_trajectory(f3); }, {"bad3.csv", "line 2", "3 fields"});

  const auto f4 = dir / "bad4.csv";
  spit(f4, "time,x,y\n1,0,0\n");
  expect_input_error([&] { read_trajectory(f4); }, {"bad4.csv", "line 1", "t_s"});

  const auto f5 = dir / "bad5.tum";
  spit(f5, "# c\n1 0 0 0 0 0 0 1\n2 nan 0 0 0 0 0 1\n");
  expect_input_error([&] { read_trajectory(f5, TrajectoryFormat::kTum); },
                     {"bad5.tum", "line 3", "position"});

  const auto f6 = dir / "bad6.tum";
  spit(f6, "1 0 0 0 0 0 0 2\n");
  expect_input_error([&] { read_trajectory(f6, TrajectoryFormat::kTum); },
                     {"bad6.tum", "line 1", "quaternion"});

  const auto f7 = dir / "bad7.txt";
  spit(f7, "1 2 3 4 5\n");
  expect_input_error([&] { read_trajectory(f7); }, {"bad7.txt", "line 1", "5"});

  const auto f8 = dir / "bad8.txt";
  spit(f8, "1 0 0 0 0 0 0 0 0 90\n2 0 0 0 0 0 0 0 0\n");
  expect_input_error([&] { read_trajectory(f8, TrajectoryFormat::kWheelInsTraj); },
                     {"bad8.txt", "line 2", "9 values", "expected 10"});

  expect_input_error([&] { read_trajectory(dir / "nope.csv"); }, {"nope.csv", "not found"});
  expect_input_error([&] { read_trajectory(dir / "x.kml"); }, {"x.kml", "KML"});

  // Writers check time order too.
  auto w = make_trajectory_writer(TrajectoryFormat::kCsv, dir / "order.csv");
  w->write(sample_traj_record(1));
  expect_input_error([&] { w->write(sample_traj_record(0)); },
                     {"order.csv", "record 1", "does not increase"});
}

TEST(IoText, SignificantDigitsMatchToChars) {
  // append_double(v, p) takes a fast path for fixed notation; it must write exactly what
  // std::to_chars(general, p) writes, near-ties and exact ties included.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mant(1.0, 10.0);
  std::uniform_int_distribution<int> expo(-7, 16);
  int mismatches = 0, n = 0;
  for (int p : {1, 3, 6, 9, 10, 12, 15})
    for (int i = 0; i < 40000; ++i, ++n) {
      double v = mant(rng) * std::pow(10.0, expo(rng));
      if (i % 2) v = -v;
      if (i % 97 == 0) v = std::round(v);          // integers, trailing zeros
      if (i % 89 == 0) v = 9.999999999999 * std::pow(10.0, expo(rng));  // carries
      std::string got;
      append_double(got, v, p);
      char buf[64];
      const auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, p);
      const std::string want(buf, res.ptr);
      if (got != want) {
        ++mismatches;
        const double g = std::stod(got), w = std::stod(want);
        ASSERT_LE(std::abs(g - w), 1.5 * std::pow(10.0, std::floor(std::log10(std::abs(w))) - p + 1))
            << v << " p=" << p << ": " << got << " vs " << want;
      }
    }
  EXPECT_EQ(mismatches, 0) << mismatches << " of " << n;
  // Products that round onto the wrong side of a half, and exact binary ties.
  for (double v : {0.0, -0.0, 1e-4, 0.00012345678901, 123456789.0, 1e300, -5e-300, 9.9999999995,
                   0.069334085470050003, 0.125, 0.375, 2.5, -3.5, 1234.5625})
    for (int p : {1, 2, 6, 9, 10, 12}) {
      std::string got;
      append_double(got, v, p);
      char buf[64];
      const auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, p);
      EXPECT_EQ(got, std::string(buf, res.ptr)) << v;
    }
}
