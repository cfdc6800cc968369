#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "io_test_util.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/manifest_draft.hpp"
#include "wheelins/io/odometer.hpp"

using namespace wheelins;
using namespace wheelins::iotest;

namespace {

constexpr double kT0 = 132030.0;     // GPS seconds of week at the first IMU record
constexpr double kMoveAt = 3.0;      // the vehicle starts rolling 3 s in
constexpr double kLat = 30.5281, kLon = 114.3567, kH = 21.5, kYaw = 123.25;

/// An IMU file: static until kMoveAt, then a wheel rolling at 10 rad/s about x.
void write_imu(const std::filesystem::path& f, double rate, double start, double seconds) {
  ImuFileWriter w(f, SampleFormat::kRate, FileLayout::kBinary, true);
  const int n = static_cast<int>(seconds * rate);
  for (int i = 0; i < n; ++i) {
    ImuRow r;
    r.t = start + i / rate;
    r.gyro = Vec3(r.t - kT0 < kMoveAt ? 1e-3 : -10.0, 2e-4, -1e-4);
    r.accel = Vec3(0.01, 0.02, -9.79);
    w.write_row(r);
  }
  w.commit();
}

/// 11-column truth at 50 Hz from kT0 - 1: static until kMoveAt, then 1 m/s north.
void write_truth11(const std::filesystem::path& f, double seconds) {
  std::vector<double> v;
  for (int i = 0; i < static_cast<int>(seconds * 50) + 1; ++i) {
    const double t = kT0 - 1.0 + i / 50.0;
    const double vn = t - kT0 < kMoveAt ? 0.0 : 1.0;
    v.insert(v.end(), {2190.0, t, kLat + 1e-6 * i, kLon, kH, vn, 0.0, 0.0, 0.5, -0.3, kYaw});
  }
  write_doubles(f, v);
}

void write_truth5(const std::filesystem::path& f, double seconds) {
  std::vector<double> v;
  for (int i = 0; i < static_cast<int>(seconds * 10) + 1; ++i) {
    const double t = kT0 + i / 10.0;
    v.insert(v.end(), {t, kLat, kLon + 1e-6 * i, kH, 0.0});
  }
  write_doubles(f, v);
}

void write_odo(const std::filesystem::path& f, double seconds) {
  OdoWriter w(f, FileLayout::kBinary, true);
  for (int i = 0; i < static_cast<int>(seconds * 2); ++i) {
    const double t = kT0 + 0.005 + 0.5 * i;
    w.write({t, t - kT0 < kMoveAt + 1.0 ? 0.0 : 1.4});  // odometer: moving from 4 s
  }
  w.commit();
}

/// The multi-IMU layout: left/right wheels (C1-C4 at 200 Hz), body (C1, C2 at 100 Hz).
void make_multi(const ScratchDir& dir, bool truth11) {
  for (const char* side : {"left-wheel-imu", "right-wheel-imu"})
    for (int c = 1; c <= 4; ++c)
      write_imu(dir / (std::string(side) + "/tri_C" + std::to_string(c) + "_imu.bin"), 200.0,
                kT0 + 0.001 * c, 8.0);
  for (int c = 1; c <= 2; ++c)
    write_imu(dir / ("body-imu/tri_C" + std::to_string(c) + "_imu.bin"), 100.0, kT0, 8.0);
  if (truth11) write_truth11(dir / "ground_truth/GINS-body.bin", 10.0);
  else write_truth5(dir / "ground_truth/GINS-body.bin", 10.0);
}

std::string slurp(const std::filesystem::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const WarningSink kQuiet = [](const std::string&) {};

}  // namespace

TEST(IoManifestDraft, MultiImuLayoutWithFullTruth) {
  ScratchDir dir;
  make_multi(dir, true);
  const auto out = dir / "manifest.yaml";
  const ManifestDraft d = draft_manifest(dir.path(), out);
  EXPECT_EQ(d.layout, "multi-IMU");
  const Manifest& m = d.manifest;
  ASSERT_EQ(m.modules.size(), 10u);
  EXPECT_EQ(m.modules[0].name, "left-C1");
  EXPECT_EQ(m.modules[0].group, "left-wheel");
  EXPECT_EQ(m.modules[0].chip, "C1");
  EXPECT_EQ(m.modules[0].kind, ModuleKind::kWheel);
  EXPECT_EQ(m.modules[0].file, std::filesystem::path("left-wheel-imu/tri_C1_imu.bin"));
  EXPECT_EQ(m.modules[7].name, "right-C4");
  EXPECT_EQ(m.modules[8].name, "body-C1");
  EXPECT_EQ(m.modules[8].kind, ModuleKind::kBody);
  EXPECT_EQ(m.modules[0].rate_hz, 200.0);
  EXPECT_EQ(m.modules[9].rate_hz, 100.0);
  EXPECT_LT(m.modules[0].p_inV.y(), 0.0);  // left wheel on the left
  EXPECT_GT(m.modules[4].p_inV.y(), 0.0);
  EXPECT_EQ(m.truth_file, std::filesystem::path("ground_truth/GINS-body.bin"));
  EXPECT_FALSE(m.odometer_file);
  // Static period: from the latest first record (C4 at +4 ms) to 0.5 s before the truth moves.
  EXPECT_DOUBLE_EQ(m.static_start, kT0 + 0.004);
  EXPECT_NEAR(m.static_end, kT0 + kMoveAt - 0.5, 1e-6);
  // Origin and heading from the first truth record at or after the start (kT0 + 0.02).
  EXPECT_NEAR(m.origin.lat, (kLat + 1e-6 * 51) * kDeg, 1e-12);
  EXPECT_NEAR(m.origin.lon, kLon * kDeg, 1e-12);
  EXPECT_EQ(m.origin.h, kH);
  EXPECT_NEAR(m.initial_heading, kYaw * kDeg, 1e-12);
  EXPECT_EQ(m.track_width, 0.33);

  save_manifest(m, out, d.notes);
  const Manifest back = load_manifest(out, kQuiet);
  EXPECT_EQ(back.modules.size(), 10u);
  EXPECT_TRUE(std::filesystem::exists(back.resolve(back.modules[9].file)));
  const std::string text = slurp(out);
  EXPECT_HAS(text, "wheel_radius_m: 0.097");
  EXPECT_HAS(text, "# TODO: measure");
  std::size_t todo = 0;
  for (std::size_t p = text.find("TODO: measure"); p != std::string::npos; p = text.find("TODO: measure", p + 1)) ++todo;
  // 8 wheel modules x (radius, lever arm, position, mounting, axle sign) + 2 body x 2 + track.
  EXPECT_EQ(todo, 8u * 5u + 2u * 2u + 1u);
  bool mentions_radius = false;
  for (const auto& t : d.todo) mentions_radius |= t.find("wheel_radius_m") != std::string::npos;
  EXPECT_TRUE(mentions_radius);
}

TEST(IoManifestDraft, PositionOnlyTruthAndOdometer) {
  ScratchDir dir;
  make_multi(dir, false);
  write_odo(dir / "odo.bin", 8.0);
  const ManifestDraft d = draft_manifest(dir.path(), dir / "sub/m.yaml");
  const Manifest& m = d.manifest;
  EXPECT_EQ(m.modules[0].file, std::filesystem::path("../left-wheel-imu/tri_C1_imu.bin"));
  EXPECT_EQ(m.odometer_file, std::filesystem::path("../odo.bin"));
  EXPECT_NEAR(m.origin.lon, (kLon + 1e-6) * kDeg, 1e-12);  // first record at/after kT0 + 0.004
  EXPECT_EQ(m.initial_heading, 0.0);
  bool heading_todo = false;
  for (const auto& t : d.todo) heading_todo |= t.find("heading") != std::string::npos;
  EXPECT_TRUE(heading_todo);
  EXPECT_NEAR(m.static_end, kT0 + 0.005 + kMoveAt + 1.0 - 0.5, 1e-6);  // from the odometer
  EXPECT_HAS(d.notes.comments.at("static_period_s"), "odometer");
}

TEST(IoManifestDraft, SingleImuLayout) {
  ScratchDir dir;
  write_imu(dir / "ADIS16465_imu.bin", 200.0, kT0, 6.0);
  write_truth11(dir / "GINS.bin", 8.0);
  write_odo(dir / "odo.bin", 6.0);
  const ManifestDraft d = draft_manifest(dir.path(), dir / "manifest.yaml");
  EXPECT_EQ(d.layout, "single-IMU");
  ASSERT_EQ(d.manifest.modules.size(), 1u);
  EXPECT_EQ(d.manifest.modules[0].name, "ADIS16465");
  EXPECT_EQ(d.manifest.modules[0].kind, ModuleKind::kWheel);
  EXPECT_EQ(d.manifest.truth_file, std::filesystem::path("GINS.bin"));
  EXPECT_EQ(d.manifest.odometer_file, std::filesystem::path("odo.bin"));
  EXPECT_NEAR(d.manifest.static_end, kT0 + kMoveAt - 0.5, 1e-6);
  EXPECT_EQ(d.manifest.track_width, 0.0);
}

TEST(IoManifestDraft, WheelGyroGivesTheStaticPeriodWithoutTruth) {
  ScratchDir dir;
  write_imu(dir / "w_imu.bin", 200.0, kT0, 6.0);
  const ManifestDraft d = draft_manifest(dir.path(), dir / "manifest.yaml");
  EXPECT_NEAR(d.manifest.static_end, kT0 + kMoveAt - 0.5, 1e-6);
  EXPECT_HAS(d.notes.comments.at("static_period_s"), "wheel gyro");
  EXPECT_FALSE(d.manifest.truth_file);
  EXPECT_HAS(d.notes.comments.at("initial.lat_deg"), "TODO");
}

TEST(IoManifestDraft, UnknownLayoutAndBadData) {
  ScratchDir dir;
  EXPECT_HAS(error_of([&] { draft_manifest(dir.path(), dir / "m.yaml"); }), "no recordings found");
  EXPECT_HAS(error_of([&] { draft_manifest(dir / "nope", dir / "m.yaml"); }), "nope': directory not found");
  write_doubles(dir / "bad_imu.bin", {0, 0, 0, 0, 0, 0, 9.8, 0, 0, 0, 0, 0, 0, 9.8});
  EXPECT_HAS(error_of([&] { draft_manifest(dir.path(), dir / "m.yaml"); }),
             "bad_imu.bin': record 1 (0-based), column 0 (t): time 0 repeats");
}

// ------------------------------------------------------------------ the CLI command

namespace {
int run_cli(const std::string& args, std::string* output = nullptr) {
  const std::string cmd = std::string(WHEELINS_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  std::string out;
  std::array<char, 512> buf;
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int rc = pclose(p);
  if (output) *output = out;
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
}  // namespace

TEST(IoManifestCommand, WritesRefusesToOverwriteAndHonoursForce) {
  ScratchDir dir;
  make_multi(dir, true);
  std::string out;
  ASSERT_EQ(run_cli("manifest '" + dir.path().string() + "'", &out), 0) << out;
  EXPECT_HAS(out, "manifest.yaml");
  EXPECT_HAS(out, "wheel_radius_m");
  const Manifest m = load_manifest(dir / "manifest.yaml", kQuiet);
  EXPECT_EQ(m.modules.size(), 10u);
  EXPECT_EQ(run_cli("manifest '" + dir.path().string() + "'", &out), 2);
  EXPECT_HAS(out, "error: ");
  EXPECT_HAS(out, "already exists");
  EXPECT_EQ(run_cli("manifest --force '" + dir.path().string() + "'", &out), 0) << out;
  ASSERT_EQ(run_cli("manifest '" + dir.path().string() + "' -o '" + (dir / "cfg/x.yaml").string() + "'", &out), 0) << out;
  const Manifest x = load_manifest(dir / "cfg/x.yaml", kQuiet);
  EXPECT_TRUE(std::filesystem::exists(x.resolve(x.modules[0].file)));
  EXPECT_TRUE(std::filesystem::exists(x.resolve(*x.truth_file)));
  EXPECT_EQ(run_cli("manifest '" + (dir / "nothing").string() + "'", &out), 2);
  EXPECT_HAS(out, "directory not found");
}
