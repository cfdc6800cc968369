// `wheelins evaluate` end to end: files in, table and JSON out, exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "wheelins/io/trajectory.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/nav/types.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

struct CmdResult {
  int code;
  std::string out, err;
};

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class EvalCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("wheelins_evalcli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  CmdResult run(const std::string& args) {
    const auto out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string("'") + WHEELINS_BINARY + "' evaluate " + args + " >'" +
                            out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
  }
  // Truth: north at 1 m/s for 300 s, heading 0; trajectory: east error 0.01 * s,
  // heading 1 deg too high. Drift: r_k = 0.01 k l / (k l) = 1 % for k = 1..3.
  void make_files(double sigma = 1.0) {
    const earth::Geodetic origin{30.5 * kDeg, 114.3 * kDeg, 20.0};
    const earth::LocalFrame frame(origin);
    TruthWriter tw(dir_ / "GINS.bin", false, 2200);
    auto w = make_trajectory_writer(TrajectoryFormat::kCsv, dir_ / "traj.csv");
    for (int i = 0; i <= 300; ++i) {
      TruthRecord t;
      t.t = 1000.0 + i;
      t.lla = frame.geodetic_from_ned(Vec3(i, 0, 0));
      t.v_ned = Vec3(1, 0, 0);
      tw.write(t);
      TrajectoryRecord r;
      r.t = t.t;
      r.p_inN = Vec3(i, 0.01 * i, 0);
      r.lla = frame.geodetic_from_ned(r.p_inN);
      r.rpy = Vec3(0, 0, 1.0 * kDeg);
      r.p_std = Vec3(sigma, sigma, sigma);
      w->write(r);
    }
    tw.commit();
    w->commit();
  }
  std::string p(const char* name) { return "'" + (dir_ / name).string() + "'"; }
  fs::path dir_;
};

double json_value(const std::string& json, const std::string& key) {
  const auto k = json.find("\"" + key + "\":");
  if (k == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + k + key.size() + 3, nullptr);
}

}  // namespace

TEST_F(EvalCliTest, TableAndJson) {
  make_files();
  const CmdResult r = run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --json -");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NEAR(json_value(r.out, "drift_rate_pct"), 1.0, 1e-6) << r.out;
  EXPECT_NEAR(json_value(r.out, "heading_rmse_deg"), 1.0, 1e-6);
  EXPECT_NEAR(json_value(r.out, "distance_m"), 300.0, 1e-5);
  EXPECT_NEAR(json_value(r.out, "duration_s"), 300.0, 1e-9);
  EXPECT_NEAR(json_value(r.out, "max_error_m"), 3.0, 1e-6);
  EXPECT_NEAR(json_value(r.out, "within_3sigma_fraction"), 1.0, 0.0);
  {  // three segments of 100 m, each 1 %
    const auto b = r.out.find("\"drift_curve_pct\": [");
    ASSERT_NE(b, std::string::npos) << r.out;
    std::istringstream arr(r.out.substr(b + 20, r.out.find(']', b) - b - 20));
    std::vector<double> curve;
    for (std::string item; std::getline(arr, item, ',');) curve.push_back(std::stod(item));
    ASSERT_EQ(curve.size(), 3u) << r.out;
    for (double c : curve) EXPECT_NEAR(c, 1.0, 1e-6);
  }
  // The table went to stderr because stdout carries the JSON.
  EXPECT_NE(r.err.find("position drift rate"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1.000 %"), std::string::npos) << r.err;

  // JSON to a file; the table on stdout. An existing file needs --force.
  const CmdResult f = run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --json " +
                    p("m.json") + " --segment 150");
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_NE(f.out.find("heading RMSE"), std::string::npos);
  EXPECT_NEAR(json_value(slurp(dir_ / "m.json"), "segment_m"), 150.0, 0.0);
  const CmdResult again = run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --json " +
                        p("m.json"));
  EXPECT_EQ(again.code, 2);
  EXPECT_NE(again.err.find("already exists"), std::string::npos) << again.err;
  const CmdResult forced = run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --json " +
                         p("m.json") + " --force --series " + p("s.csv"));
  EXPECT_EQ(forced.code, 0) << forced.err;
  EXPECT_NEAR(json_value(slurp(dir_ / "m.json"), "segment_m"), 100.0, 0.0);
  EXPECT_EQ(slurp(dir_ / "s.csv").rfind("t_s,distance_m,err_n_m", 0), 0u);
}

// The east error 0.01 s m against a 1-sigma of 1 m: mean NEES about 3 (consistent enough, no
// warning); against 0.1 m: 100 times that, and the sigmas are said to understate the error.
TEST_F(EvalCliTest, SigmasThatUnderstateTheErrorAreReported) {
  make_files(1.0);
  const CmdResult ok = run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --json -");
  ASSERT_EQ(ok.code, 0) << ok.err;
  const double nees = json_value(ok.out, "mean_nees_h");
  EXPECT_NEAR(nees, 3.0, 0.05) << ok.out;
  EXPECT_EQ(ok.err.find("understate"), std::string::npos) << ok.err;
  fs::remove(dir_ / "GINS.bin");
  fs::remove(dir_ / "traj.csv");
  make_files(0.1);
  const CmdResult bad = run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --json -");
  ASSERT_EQ(bad.code, 0) << bad.err;
  EXPECT_NEAR(json_value(bad.out, "mean_nees_h"), 100.0 * nees, 1e-6 * nees) << bad.out;
  EXPECT_NE(bad.err.find("1-sigma figures understate its error: mean horizontal NEES"),
            std::string::npos)
      << bad.err;
}

TEST_F(EvalCliTest, BadInputExitsTwo) {
  make_files();
  const CmdResult missing = run("--truth " + p("nope.bin") + " --traj " + p("traj.csv"));
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("error: "), std::string::npos);
  EXPECT_NE(missing.err.find("nope.bin"), std::string::npos) << missing.err;

  std::ofstream(dir_ / "bad.csv") << "t_s,north_m,east_m,down_m\n1,2,3\n";
  const CmdResult bad = run("--truth " + p("GINS.bin") + " --traj " + p("bad.csv"));
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("bad.csv': line 2"), std::string::npos) << bad.err;

  const CmdResult fmt = run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --format xyz");
  EXPECT_EQ(fmt.code, 2);
  EXPECT_NE(fmt.err.find("xyz"), std::string::npos);

  const CmdResult origin =
      run("--truth " + p("GINS.bin") + " --traj " + p("traj.csv") + " --origin 30,abc,0");
  EXPECT_EQ(origin.code, 2);
  EXPECT_NE(origin.err.find("--origin"), std::string::npos);
}

// A GNSS log as the car's (Timestamp in tenths of a second, a 5 Hz fix repeated at 100 Hz)
// given directly as the truth, its clock 50 s behind, its antenna 1 m ahead of and 1.5 m
// above the trajectory's point; the trajectory drives north at 5 m/s with its heading 1 deg
// off. The heading comes from the course.
TEST_F(EvalCliTest, GnssCsvTruthWithTimeScaleOffsetAntennaAndCourse) {
  const earth::Geodetic origin{32.7655 * kDeg, 35.0136 * kDeg, 450.0};
  const earth::LocalFrame frame(origin);
  {
    std::ofstream csv(dir_ / "GNSS.csv");
    csv << "Timestamp,Lat_GNSS,Long_GNSS,Height_GNSS,Acc_X\n";
    for (int row = 0; row <= 12000; ++row) {
      const double t = 0.2 * (row / 20);
      const earth::Geodetic g = frame.geodetic_from_ned(Vec3(5.0 * t + 1.0, 0, -1.5));
      char buf[160];
      std::snprintf(buf, sizeof buf, "%.1f,%.10f,%.10f,%.4f,0.01\n", 0.1 * row, g.lat / kDeg, g.lon / kDeg, g.h);
      csv << buf;
    }
    auto w = make_trajectory_writer(TrajectoryFormat::kCsv, dir_ / "traj.csv");
    for (int i = 0; i <= 2400; ++i) {
      TrajectoryRecord r;
      r.t = 50.0 + 0.05 * i;
      r.p_inN = Vec3(5.0 * 0.05 * i, 0, 0);
      r.lla = frame.geodetic_from_ned(r.p_inN);
      r.rpy = Vec3(0, 0, 1.0 * kDeg);
      w->write(r);
    }
    w->commit();
  }
  const std::string base = "--truth " + p("GNSS.csv") + " --traj " + p("traj.csv") +
                           " --truth-time-scale 0.1 --truth-time-offset 50 --json -";
  const CmdResult r = run(base + " --antenna 1,0,-1.5");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"truth_layout\": \"text\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"heading_source\": \"course\""), std::string::npos) << r.out;
  EXPECT_NEAR(json_value(r.out, "truth_records"), 601.0, 0.0);
  EXPECT_NEAR(json_value(r.out, "epochs"), 601.0, 0.0);
  EXPECT_NEAR(json_value(r.out, "heading_rmse_deg"), 1.0, 1e-6);
  // The lever arm turned by the 1 deg heading error: 1 m x sin(1 deg) to the side.
  EXPECT_NEAR(json_value(r.out, "max_error_m"), std::sin(1.0 * kDeg), 1e-4);
  EXPECT_NEAR(json_value(r.out, "final_error_over_distance_pct"), 100.0 * std::sin(1.0 * kDeg) / 600.0, 1e-5);
  EXPECT_NEAR(json_value(r.out, "truth_time_offset_s"), 50.0, 0.0);
  EXPECT_NE(r.err.find("text: columns: time 'Timestamp' (0) x 0.1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("12001 rows, 11400 repeating the fix before them, 601 fixes"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("antenna at 1.000 / 0.000 / -1.500 m"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("truth time offset +50"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("truth quality: no gaps, jumps or repeated fixes"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("from the course"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("final error / distance"), std::string::npos) << r.err;

  // Without the lever arm the antenna is 1 m ahead of the trajectory's point.
  const CmdResult no_arm = run(base);
  ASSERT_EQ(no_arm.code, 0) << no_arm.err;
  EXPECT_NEAR(json_value(no_arm.out, "max_error_m"), 1.0, 1e-4);
  // TUM options on a text truth, and a bad antenna, are refused.
  const CmdResult tum_opt = run(base + " --truth-origin 30,114,0");
  EXPECT_EQ(tum_opt.code, 2);
  EXPECT_NE(tum_opt.err.find("for a TUM truth"), std::string::npos) << tum_opt.err;
  const CmdResult bad_arm = run(base + " --antenna 1,0");
  EXPECT_EQ(bad_arm.code, 2);
  EXPECT_NE(bad_arm.err.find("--antenna"), std::string::npos) << bad_arm.err;
}

// A TUM truth in NED (what wheelins writes) about a given origin: the attitude is the truth's
// heading; without the origin it cannot be placed.
TEST_F(EvalCliTest, TumTruthWithFrameAndOrigin) {
  make_files();
  const earth::Geodetic origin{30.5 * kDeg, 114.3 * kDeg, 20.0};
  const earth::LocalFrame frame(origin);
  auto w = make_trajectory_writer(TrajectoryFormat::kTum, dir_ / "truth.tum");
  for (int i = 0; i <= 300; ++i) {
    TrajectoryRecord t;
    t.t = 1000.0 + i;
    t.p_inN = Vec3(i, 0, 0);
    w->write(t);
  }
  w->commit();
  const CmdResult r = run("--truth " + p("truth.tum") + " --traj " + p("traj.csv") +
                          " --truth-frame ned --truth-origin 30.5,114.3,20 --json -");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"truth_layout\": \"tum\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"heading_source\": \"truth\""), std::string::npos) << r.out;
  EXPECT_NEAR(json_value(r.out, "drift_rate_pct"), 1.0, 1e-6);
  EXPECT_NEAR(json_value(r.out, "heading_rmse_deg"), 1.0, 1e-6);
  EXPECT_NE(r.err.find("TUM in NED (body FRD)"), std::string::npos) << r.err;
  const CmdResult no_origin = run("--truth " + p("truth.tum") + " --traj " + p("traj.csv"));
  EXPECT_EQ(no_origin.code, 2);
  EXPECT_NE(no_origin.err.find("origin"), std::string::npos) << no_origin.err;
}
