// The survey (what IMU recordings say of their modules without a manifest) and the checks of
// a manifest against its data before a run: a small simulated triple dataset (two
// Wheel-IMUs, a Body-IMU, one chip each, 90 s with a 5 s static start) surveyed as it is,
// then with its files or its manifest trapped the ways an installation goes wrong (a wheel
// IMU mounted about another axis or turned round, a clock offset, a body IMU upside down or
// turned, kinds and sides mixed up); the clock fits on synthetic signals; the reference
// track's time unit and offset; and `wheelins import` of vendor tables end to end.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "dataset_test_util.hpp"
#include "io_test_util.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/math/rotation.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/sim/simulator.hpp"
#include "wheelins/survey/checks.hpp"
#include "wheelins/survey/clock.hpp"
#include "wheelins/survey/dataset.hpp"
#include "wheelins/survey/draft.hpp"
#include "wheelins/survey/reference_clock.hpp"

namespace {
using namespace wheelins;
using iotest::error_of;
using dstest::CmdResult;
using dstest::edit_module_text;
using dstest::number_after;
using dstest::read_doubles;
using dstest::wheelins_cli;
using dstest::write_table;
namespace fs = std::filesystem;

const std::vector<std::string> kModules{"left-C1", "right-C1", "body-C1"};
constexpr int kLeft = 0, kRight = 1, kBody = 2;  // also the simulator's group indices

// ------------------------------------------------------------------ IMU files and messages

/// Rewrites an IMU file (rows of t, gyro xyz, accel xyz) through `edit` on each row.
void edit_rows(const fs::path& file, const std::function<void(double*)>& edit) {
  std::vector<double> v = read_doubles(file);
  EXPECT_EQ(v.size() % 7, 0u) << file;
  for (std::size_t k = 0; k + 7 <= v.size(); k += 7) edit(&v[k]);
  iotest::write_doubles(file, v);
}

/// The gyro and the accel of every row in new sensor axes: v' = R v.
void rotate_rows(const fs::path& file, const Mat3& R) {
  edit_rows(file, [&](double* r) {
    const Vec3 g = R * Vec3(r[1], r[2], r[3]), a = R * Vec3(r[4], r[5], r[6]);
    for (int i = 0; i < 3; ++i) r[1 + i] = g[i], r[4 + i] = a[i];
  });
}

/// (x, y, z) -> (y, z, x): the new x is the old y, ..., so the old x (a simulated wheel's
/// axle) becomes the new z.
Mat3 cyclic_to_z() {
  Mat3 R = Mat3::Zero();
  R(0, 1) = R(1, 2) = R(2, 0) = 1.0;
  return R;
}

/// The line of a (multi-line) message that holds `needle` ("" if none).
std::string line_with(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  if (at == std::string::npos) return "";
  const std::size_t from = text.rfind('\n', at), to = text.find('\n', at);
  return text.substr(from == std::string::npos ? 0 : from + 1, to == std::string::npos ? std::string::npos : to - from - 1);
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kDeg;
}

std::size_t index_of(const Manifest& m, const std::string& name) {
  for (std::size_t i = 0; i < m.modules.size(); ++i)
    if (m.modules[i].name == name) return i;
  ADD_FAILURE() << "no module " << name;
  return 0;
}

/// The largest horizontal-and-vertical distance between two runs' records of equal times.
double max_difference(const std::vector<TrajectoryRecord>& a, const std::vector<TrajectoryRecord>& b) {
  EXPECT_EQ(a.size(), b.size());
  if (a.empty() || a.size() != b.size()) return 1e300;
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].t, b[k].t) << "record " << k;
    worst = std::max(worst, (a[k].p_inN - b[k].p_inN).norm());
  }
  return worst;
}

// ------------------------------------------------------------------ the dataset

/// One simulated triple dataset for the suite: the field profile (vibration, slip, skid,
/// calibration residuals, a few ms of clock offset per module), one chip per module, 90 s
/// of which the first 5 s are static (about 105 m with turns and stops).
class Survey : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("wheelins-survey-" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    sim::SimConfig cfg;
    cfg.chips = 1;
    cfg.duration = 90.0;
    cfg.static_duration = 5.0;
    cfg.write_ideal = false;
    sim_ = new sim::Simulation(cfg);
    sim_->write(*dir_ / "data", false, false);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete sim_;
    delete baseline_;
    dir_ = nullptr;
    sim_ = nullptr;
    baseline_ = nullptr;
  }

  static fs::path data() { return *dir_ / "data"; }
  static Manifest manifest(const fs::path& d) { return load_manifest(d / "manifest.yaml", {}); }
  static fs::path imu_file(const fs::path& d, int group) {
    return d / (std::string(sim::Simulation::group_dir(group))) / "tri_C1_imu.bin";
  }
  /// A copy of the dataset (its manifest, IMU files, truth and odometer) to trap.
  static fs::path variant(const std::string& name) {
    const fs::path d = *dir_ / name;
    fs::remove_all(d);
    fs::create_directories(d);
    for (const char* f : {"manifest.yaml", "GINS.bin", "odo.bin"}) fs::copy_file(data() / f, d / f);
    for (int g = 0; g < 3; ++g) {
      fs::create_directories(imu_file(d, g).parent_path());
      fs::copy_file(imu_file(data(), g), imu_file(d, g));
    }
    return d;
  }
  /// The true clock offset of module g to the body's: what the survey should find.
  static double true_offset(int g) { return sim_->module(g).time_offset - sim_->module(kBody).time_offset; }

  static RunRequest request(const Manifest& m, const std::vector<std::string>& modules) {
    RunRequest r;
    r.manifest = m;
    r.modules = modules;
    r.progress = false;
    r.formats = {TrajectoryFormat::kCsv};
    return r;
  }
  /// A run of `modules` held against the data first: its vehicle records.
  static std::vector<TrajectoryRecord> navigate(const Manifest& m, const std::vector<std::string>& modules,
                                                bool data_checks = true) {
    RunRequest r = request(m, modules);
    r.data_checks = data_checks;
    std::vector<TrajectoryRecord> out;
    r.on_record = [&](const TrajectoryRecord& rec) { out.push_back(rec); };
    run_navigation(r);
    return out;
  }
  /// The InputError of a run (the checks come before any navigating).
  static std::string run_error(const Manifest& m, const std::vector<std::string>& modules) {
    return error_of([&] { run_navigation(request(m, modules)); });
  }
  static std::vector<std::string> triple(const Manifest& m) { return configuration_modules(m, "triple", {}); }
  /// The triple run of the untouched dataset.
  static const std::vector<TrajectoryRecord>& baseline() {
    if (!baseline_) {
      const Manifest m = manifest(data());
      baseline_ = new std::vector<TrajectoryRecord>(navigate(m, triple(m)));
    }
    return *baseline_;
  }
  static survey::DatasetSurvey survey_of(const Manifest& m) {
    return survey::survey_modules(survey::survey_inputs(m, kModules));
  }

  static fs::path* dir_;
  static sim::Simulation* sim_;
  static std::vector<TrajectoryRecord>* baseline_;
};
fs::path* Survey::dir_ = nullptr;
sim::Simulation* Survey::sim_ = nullptr;
std::vector<TrajectoryRecord>* Survey::baseline_ = nullptr;

// ------------------------------------------------------------------ 1. the clean dataset

TEST_F(Survey, CleanTripleDatasetIsReadRight) {
  const Manifest m = manifest(data());
  const survey::DatasetSurvey s = survey_of(m);
  std::string notes;
  for (const auto& n : s.notes) notes += n + "\n";
  SCOPED_TRACE(survey::survey_report(s) + notes);
  ASSERT_EQ(s.modules.size(), 3u);
  for (int g : {kLeft, kRight}) {
    const survey::ModuleFinding& f = *s.find(kModules[g]);
    SCOPED_TRACE(f.module);
    EXPECT_EQ(f.kind, ModuleKind::kWheel);
    EXPECT_TRUE(f.traits.spins);
    EXPECT_EQ(f.traits.spin_axis, 0);
    EXPECT_EQ(f.axle_axis, 0);
    EXPECT_GT(f.traits.spin_share, 0.95);
    // The simulated wheels roll forward all the way: every turn of the axle one way.
    EXPECT_TRUE(f.forward_clear);
    EXPECT_LT(f.traits.spin_direction, -0.9);
    EXPECT_EQ(f.axle_sign, m.find(f.module)->axle_sign);
    EXPECT_FALSE(f.steered);
    EXPECT_TRUE(std::isfinite(f.yaw_departure));
    EXPECT_LT(f.yaw_departure, 0.5);
    // Clocks: the body is the reference; each wheel's offset to it is the simulated one.
    ASSERT_TRUE(f.clock.found);
    EXPECT_FALSE(f.clock_reference);
    EXPECT_GT(f.clock.correlation, 0.9);
    // The fits' own 1 sigma is tens of ms here (cruising stretches carry little timing),
    // the simulated offsets a few ms: the fit is within 2 sigma of them and 30 ms.
    EXPECT_LT(f.clock.sigma, 0.06);
    EXPECT_NEAR(f.clock.offset, true_offset(g), std::min(2.0 * f.clock.sigma, 0.03))
        << "simulated clock offset " << true_offset(g) << " s, sigma " << f.clock.sigma;
  }
  // Sides: the left wheel (y < 0 in the manifest) on the left.
  EXPECT_LT(m.find("left-C1")->p_inV.y(), 0.0);
  EXPECT_EQ(s.find("left-C1")->side, -1);
  EXPECT_EQ(s.find("right-C1")->side, +1);

  const survey::ModuleFinding& b = *s.find("body-C1");
  EXPECT_EQ(b.kind, ModuleKind::kBody);
  EXPECT_FALSE(b.traits.spins);
  EXPECT_TRUE(b.clock_reference);
  EXPECT_TRUE(b.traits.rest_found);
  // A body's axes against the simulated mounting (C_b^v): up is -z of v, forward x of v.
  const Mat3 C_BtoV = dcm_from_euler(sim_->module(kBody).truth.mounting_rpy);
  EXPECT_LT(angle_deg(b.traits.up, C_BtoV.transpose() * -Vec3::UnitZ()), 1.0)
      << "up " << b.traits.up.transpose();
  ASSERT_TRUE(b.axes_found) << "forward fit " << b.forward_fit;
  EXPECT_LT(angle_deg(b.forward, C_BtoV.transpose() * Vec3::UnitX()), 5.0)
      << "forward " << b.forward.transpose();
  EXPECT_LT(angle_deg(b.left, C_BtoV.transpose() * -Vec3::UnitY()), 5.0);

  // The static period: from the start of the data, at least the manifest's, and the vehicle
  // at rest all through it (the simulated start is a smoothed step: the speed is still under
  // 5 mm/s 4 s after the manifest's static period ends, so the data rest longer than it).
  ASSERT_TRUE(s.static_period.has_value());
  EXPECT_GE(s.static_period->start, m.static_start);
  EXPECT_LE(s.static_period->start, m.static_start + 0.5);
  EXPECT_GE(s.static_period->end, m.static_end);
  const TruthData truth = read_truth(data() / "GINS.bin");
  double fastest = 0.0;
  for (const TruthRecord& r : truth.records)
    if (r.t >= s.static_period->start && r.t <= s.static_period->end) fastest = std::max(fastest, r.v_ned.norm());
  EXPECT_LT(fastest, 0.01) << "the vehicle moves in the static period found";
  double moving_from = 0.0;
  for (const TruthRecord& r : truth.records)
    if (r.v_ned.norm() > 0.02) {
      moving_from = r.t;
      break;
    }
  EXPECT_GT(s.static_period->end, moving_from - 1.5) << "the static period found ends long before the vehicle moves";

  // And the manifest agrees with its data: no error, no warning.
  for (const auto& c : survey::check_against_data(m, kModules, s)) ADD_FAILURE() << c.message;
}

// ------------------------------------------------------------------ 2. the spin axis

TEST_F(Survey, WheelImuSpinningAboutAnotherAxisNeedsItsAxleAxis) {
  // The left wheel's IMU mounted with its z axis along the axle: (x, y, z) -> (y, z, x).
  const fs::path d = variant("axle-axis-z");
  rotate_rows(imu_file(d, kLeft), cyclic_to_z());
  Manifest m = manifest(d);
  const survey::DatasetSurvey s = survey_of(m);
  const survey::ModuleFinding& f = *s.find("left-C1");
  EXPECT_EQ(f.kind, ModuleKind::kWheel);
  EXPECT_EQ(f.traits.spin_axis, 2);
  EXPECT_EQ(f.axle_axis, 2);
  EXPECT_EQ(f.axle_sign, 1);
  EXPECT_EQ(f.side, -1);
  EXPECT_EQ(s.find("right-C1")->axle_axis, 0);

  // The manifest's axle (x) is refused, naming the module and the axis the data show.
  const std::string e = run_error(m, triple(m));
  const std::string line = line_with(e, "module 'left-C1'");
  EXPECT_HAS(line, "axle_axis: z");
  EXPECT_HAS(line, "modules[0].axle_axis");
  EXPECT_EQ(line_with(e, "module 'right-C1'"), "") << e;
  EXPECT_EQ(line_with(e, "module 'body-C1'"), "") << e;

  // With `axle_axis: z` the sensor axes are permuted back exactly: the same trajectory.
  edit_module_text(d / "manifest.yaml", "left-C1", "    axle_sign: 1", "    axle_axis: z\n    axle_sign: 1");
  m = manifest(d);
  EXPECT_EQ(m.find("left-C1")->axle_axis, 2);
  const std::vector<TrajectoryRecord> run = navigate(m, triple(m));
  EXPECT_LT(max_difference(run, baseline()), 1e-6);
}

// ------------------------------------------------------------------ 3. the axle sign

TEST_F(Survey, WheelImuTurnedRoundNeedsItsAxleSign) {
  // The right wheel's IMU turned 180 deg about z: its x axis (the axle) points left.
  const fs::path d = variant("axle-sign");
  rotate_rows(imu_file(d, kRight), Vec3(-1.0, -1.0, 1.0).asDiagonal());
  Manifest m = manifest(d);
  const survey::DatasetSurvey s = survey_of(m);
  EXPECT_EQ(s.find("right-C1")->axle_axis, 0);
  EXPECT_EQ(s.find("right-C1")->axle_sign, -1);
  EXPECT_TRUE(s.find("right-C1")->forward_clear);
  EXPECT_EQ(s.find("left-C1")->axle_sign, 1);
  // Turned round, it is still on the right (the sides come from the spin rates' size).
  EXPECT_EQ(s.find("right-C1")->side, 1);

  // A triple run names that wheel and its axle_sign, and neither the other wheel nor the body.
  const std::string e = run_error(m, triple(m));
  EXPECT_HAS(line_with(e, "module 'right-C1'"), "modules[1].axle_sign: -1");
  EXPECT_EQ(line_with(e, "module 'left-C1'"), "") << e;
  EXPECT_EQ(line_with(e, "module 'body-C1'"), "") << e;

  // With axle_sign -1 it runs, and goes where the untouched dataset goes.
  edit_module_text(d / "manifest.yaml", "right-C1", "axle_sign: 1", "axle_sign: -1");
  m = manifest(d);
  EXPECT_EQ(m.find("right-C1")->axle_sign, -1);
  const std::vector<TrajectoryRecord> run = navigate(m, triple(m));
  // Not to the last digit: the manifest's small mounting residual (roll, pitch) is now about
  // axes turned round, and the run estimates the mounting from the data (3 mm here).
  EXPECT_LT(max_difference(run, baseline()), 0.01);
}

// ------------------------------------------------------------------ 4. clocks

TEST_F(Survey, ModuleClockOffsetIsFoundAndNamed) {
  // 37.25 s added to one module's times: a wheel, then the body (the survey's reference).
  for (int g : {kRight, kBody}) {
    const std::string name = kModules[g];
    SCOPED_TRACE(name);
    const fs::path d = variant("clock-" + name);
    edit_rows(imu_file(d, g), [](double* r) { r[0] += 37.25; });
    Manifest m = manifest(d);
    const std::string e = run_error(m, triple(m));
    const std::string line = line_with(e, "module '" + name + "'");
    EXPECT_HAS(line, "time_offset_s: ");
    // The offset that puts its times back: -37.25 s plus the simulated clock offset (ms).
    const double suggested = number_after(line, "time_offset_s: ");
    EXPECT_NEAR(suggested, -37.25, 0.05) << e;
    for (const std::string& other : kModules)
      if (other != name) {
        EXPECT_EQ(line_with(e, "module '" + other + "'"), "") << e;
      }

    // With it the run is the untouched one's but for the fit's error: up to 30 ms at up to
    // 1.5 m/s (about 2 cm here).
    m.modules[index_of(m, name)].time_offset = suggested;
    const std::vector<TrajectoryRecord> run = navigate(m, triple(m));
    EXPECT_LT(max_difference(run, baseline()), 0.05);
  }
}

TEST_F(Survey, ModuleOutsideTheRunIsAnError) {
  {
    // The left wheel's data 5000 s later: they overlap the run nowhere, yet their motion is
    // the others' and the survey finds the clock.
    const fs::path d = variant("clock-far");
    edit_rows(imu_file(d, kLeft), [](double* r) { r[0] += 5000.0; });
    const Manifest m = manifest(d);
    const std::string e = run_error(m, triple(m));
    EXPECT_NEAR(number_after(line_with(e, "module 'left-C1'"), "time_offset_s: "), -5000.0, 0.05) << e;
    // The others cover the run and are not blamed.
    EXPECT_EQ(line_with(e, "module 'right-C1'"), "") << e;
    EXPECT_EQ(line_with(e, "module 'body-C1'"), "") << e;
  }
  {
    // 15 s of the left wheel's driving, 5000 s later: too short to match; the run's modules
    // are not silently left to the others.
    const fs::path d = variant("clock-lost");
    std::vector<double> rows = read_doubles(imu_file(d, kLeft)), kept;
    for (std::size_t k = 0; k + 7 <= rows.size(); k += 7)
      if (rows[k] - rows[0] >= 40.0 && rows[k] - rows[0] < 55.0)
        for (std::size_t j = 0; j < 7; ++j) kept.push_back(rows[k + j] + (j == 0 ? 5000.0 : 0.0));
    iotest::write_doubles(imu_file(d, kLeft), kept);
    const Manifest m = manifest(d);
    const survey::DatasetSurvey s = survey_of(m);
    EXPECT_FALSE(s.find("left-C1")->clock.found);
    const std::string e = run_error(m, triple(m));
    const std::string line = line_with(e, "module 'left-C1'");
    EXPECT_HAS(line, "time_offset_s");
    EXPECT_HAS(line, " 0 % of the run");
    EXPECT_EQ(line_with(e, "module 'right-C1'"), "") << e;
    EXPECT_EQ(line_with(e, "module 'body-C1'"), "") << e;
  }
}

// ------------------------------------------------------------------ 5. kinds

TEST_F(Survey, ModuleOfTheOtherKindIsAnError) {
  {
    Manifest m = manifest(data());
    m.modules[index_of(m, "body-C1")].kind = ModuleKind::kWheel;
    const std::string e = run_error(m, kModules);
    EXPECT_HAS(line_with(e, "module 'body-C1'"), "modules[2].kind: body");
    EXPECT_EQ(line_with(e, "module 'left-C1'"), "") << e;
    EXPECT_EQ(line_with(e, "module 'right-C1'"), "") << e;
  }
  {
    Manifest m = manifest(data());
    m.modules[index_of(m, "left-C1")].kind = ModuleKind::kBody;
    const std::string e = run_error(m, kModules);
    EXPECT_HAS(line_with(e, "module 'left-C1'"), "modules[0].kind: wheel");
    EXPECT_EQ(line_with(e, "module 'right-C1'"), "") << e;
    EXPECT_EQ(line_with(e, "module 'body-C1'"), "") << e;
  }
}

// ------------------------------------------------------------------ 6. sides

TEST_F(Survey, WheelsOnSwappedSidesAreAnError) {
  Manifest m = manifest(data());
  ModuleSpec& l = m.modules[index_of(m, "left-C1")];
  ModuleSpec& r = m.modules[index_of(m, "right-C1")];
  std::swap(l.p_inV.y(), r.p_inV.y());
  const std::string e = run_error(m, triple(m));
  EXPECT_HAS(line_with(e, "module 'left-C1'"), "position_v_m");
  EXPECT_HAS(line_with(e, "module 'left-C1'"), "on the vehicle's left");
  EXPECT_HAS(line_with(e, "module 'right-C1'"), "position_v_m");
  EXPECT_HAS(line_with(e, "module 'right-C1'"), "on the vehicle's right");
  EXPECT_EQ(line_with(e, "module 'body-C1'"), "") << e;
}

// ------------------------------------------------------------------ 7. a body's mounting

TEST_F(Survey, BodyImuUpsideDownIsAnError) {
  const fs::path d = variant("body-upside-down");
  rotate_rows(imu_file(d, kBody), Vec3(1.0, -1.0, -1.0).asDiagonal());
  const Manifest m = manifest(d);
  const std::string e = run_error(m, triple(m));
  const std::string line = line_with(e, "module 'body-C1'");
  EXPECT_HAS(line, "modules[2].mounting_deg");
  EXPECT_HAS(line, "+z axis points up");
  EXPECT_EQ(line_with(e, "module 'left-C1'"), "") << e;
  EXPECT_EQ(line_with(e, "module 'right-C1'"), "") << e;
}

TEST_F(Survey, BodyImuTurnedAboutTheVerticalIsAnError) {
  // The sensor turned +90 deg about its z axis: v' = Rz(90)^T v, so C_b'^v = C_b^v Rz(90)
  // and the yaw of mounting_deg grows by 90 deg.
  const fs::path d = variant("body-turned");
  rotate_rows(imu_file(d, kBody), dcm_from_euler(Vec3(0.0, 0.0, 90.0 * kDeg)).transpose());
  const Manifest m = manifest(d);
  const survey::DatasetSurvey s = survey_of(m);
  const survey::ModuleFinding& b = *s.find("body-C1");
  ASSERT_TRUE(b.axes_found) << "forward fit " << b.forward_fit;
  EXPECT_LT(angle_deg(b.forward, -Vec3::UnitY()), 5.0) << b.forward.transpose();

  const std::string e = run_error(m, triple(m));
  const std::string line = line_with(e, "module 'body-C1'");
  EXPECT_HAS(line, "modules[2].mounting_deg to about [");
  const std::size_t at = line.find("to about [");
  ASSERT_NE(at, std::string::npos) << e;
  double rpy[3];
  ASSERT_EQ(std::sscanf(line.c_str() + at, "to about [%lf, %lf, %lf]", &rpy[0], &rpy[1], &rpy[2]), 3) << line;
  const double yaw = m.find("body-C1")->mounting_rpy.z() / kDeg + 90.0;
  EXPECT_NEAR(rpy[2], yaw, 10.0) << line;
  EXPECT_EQ(line_with(e, "module 'left-C1'"), "") << e;
  EXPECT_EQ(line_with(e, "module 'right-C1'"), "") << e;
}

// ------------------------------------------------------------------ 8. without the checks

TEST_F(Survey, NoDataChecksRunsTheManifestAsItIs) {
  const fs::path d = variant("unchecked");
  rotate_rows(imu_file(d, kRight), Vec3(-1.0, -1.0, 1.0).asDiagonal());
  const Manifest m = manifest(d);
  EXPECT_HAS(run_error(m, triple(m)), "axle_sign");
  std::vector<TrajectoryRecord> run;
  EXPECT_NO_THROW(run = navigate(m, triple(m), false));
  EXPECT_EQ(run.size(), baseline().size());
  // Taken as it is, the right wheel drives backward. It went astray (62 m here) until the fault
  // handling outvoted such a wheel (docs/faults.md): now it is isolated for the run, and the run
  // stays with the untouched dataset's (0.28 m).
  EXPECT_LT(max_difference(run, baseline()), 1.0);
}

// ------------------------------------------------------------------ steering

TEST_F(Survey, SteeredWheelIsDraftedSteeredAndAWarningWhereTheManifestSaysNot) {
  // The simulated wheels are the rear ones: the survey's finding for one is set as a steered
  // wheel's would be, and the checks and the draft read it.
  Manifest m = manifest(data());
  survey::DatasetSurvey s = survey_of(m);
  for (survey::ModuleFinding& f : s.modules)
    if (f.module == "left-C1") {
      f.steered = true;
      f.yaw_lead = 0.35;
      f.yaw_departure = 0.8;
    }
  const std::vector<survey::DataCheck> checks = survey::check_against_data(m, kModules, s);
  ASSERT_EQ(checks.size(), 1u);
  EXPECT_EQ(checks[0].level, survey::DataCheck::Level::kWarning);
  EXPECT_EQ(checks[0].module, "left-C1");
  const std::string& w = checks[0].message;
  EXPECT_HAS(w, "module 'left-C1': its yaw rate leads the vehicle's by 0.35 s and departs from it by 80 %");
  EXPECT_HAS(w, "set steered: true");
  // A manifest that says so: nothing to warn about.
  for (auto& spec : m.modules)
    if (spec.name == "left-C1") spec.steered = true;
  EXPECT_TRUE(survey::check_against_data(m, kModules, s).empty());

  std::vector<survey::DraftModule> drafts;
  for (const std::string& name : kModules) {
    survey::DraftModule dm;
    dm.name = name;
    dm.file = name + "_imu.bin";
    dm.rate_hz = 200.0;
    drafts.push_back(dm);
  }
  const ManifestDraft d = survey::draft_from_survey(s, drafts, {});
  const survey::VehicleType car = survey::vehicle_type("car");
  EXPECT_EQ(d.manifest.find("left-C1")->p_inV.x(), car.wheelbase);
  EXPECT_TRUE(d.manifest.find("left-C1")->steered);
  EXPECT_EQ(d.manifest.find("right-C1")->p_inV.x(), 0.0);
  EXPECT_FALSE(d.manifest.find("right-C1")->steered);
  std::string facts;
  for (const auto& f : d.facts) facts += f + "\n";
  EXPECT_HAS(facts, "left-C1: a steered wheel");
}

// ------------------------------------------------------------------ 9. clock fits

/// A smooth signal that never repeats within the tests' spans: sines of incommensurate
/// frequencies between 0.05 and 3 Hz with random phases.
class Wave {
 public:
  explicit Wave(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 16; ++k) {
      f_.push_back(0.05 * std::pow(60.0, u(rng)));
      a_.push_back(0.5 + u(rng));
      ph_.push_back(2.0 * kPi * u(rng));
    }
  }
  double operator()(double t) const {
    double x = 0.0;
    for (std::size_t k = 0; k < f_.size(); ++k) x += a_[k] * std::sin(2.0 * kPi * f_[k] * t + ph_[k]);
    return x;
  }

 private:
  std::vector<double> f_, a_, ph_;
};

/// w(t + shift) + white noise at `from`, `from` + step, ... over `span`; with `jitter` the
/// times are uneven (each moved by up to 40 % of a step) and the signal says no step.
survey::Signal sampled(const Wave& w, double from, double span, double step, double shift, double noise,
                       std::mt19937& rng, bool jitter = false) {
  std::normal_distribution<double> n(0.0, noise);
  std::uniform_real_distribution<double> j(-0.4 * step, 0.4 * step);
  survey::Signal s;
  for (double t = from; t <= from + span; t += step) {
    const double tk = jitter ? t + j(rng) : t;
    s.t.push_back(tk);
    s.x.push_back(w(tk + shift) + n(rng));
  }
  s.step = jitter ? 0.0 : step;
  return s;
}

TEST(SurveyClock, KnownOffsetsAreFoundWithinTheirSigma) {
  const Wave w(7);
  std::mt19937 rng(11);
  // a(t) = w(t), b(t) = w(t + o): then a(t) = b(t - o), the offset the fit returns. b's
  // 300 s are placed to cover w from 40 s to 340 s, inside a's 400 s.
  for (const double o : {2.345, -7.89, 133.0, -133.0}) {
    for (const bool jitter : {false, true}) {
      SCOPED_TRACE("offset " + std::to_string(o) + (jitter ? ", uneven times" : ""));
      const survey::Signal a = sampled(w, 0.0, 400.0, 0.01, 0.0, 0.3, rng);
      const survey::Signal b = sampled(w, 40.0 - o, 300.0, 0.02, o, 0.3, rng, jitter);
      const survey::ClockFit fit = survey::fit_clock_offset(a, b);
      ASSERT_TRUE(fit.found);
      EXPECT_LT(fit.sigma, 0.005);
      EXPECT_GT(fit.sigma, 0.0);
      EXPECT_NEAR(fit.offset, o, 2.0 * fit.sigma) << "sigma " << fit.sigma;
      EXPECT_GT(fit.correlation, 0.9);
      EXPECT_NEAR(fit.overlap, 300.0, 1.0);
    }
  }
}

TEST(SurveyClock, UnrelatedSignalsCorrelateLittle) {
  std::mt19937 rng(5);
  survey::ClockOptions long_overlap;
  long_overlap.min_overlap = 200.0;
  for (std::uint32_t seed = 20; seed < 30; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const survey::Signal a = sampled(Wave(seed), 0.0, 300.0, 0.01, 0.0, 0.3, rng);
    const survey::Signal b = sampled(Wave(seed + 100), 0.0, 300.0, 0.01, 0.0, 0.3, rng);
    // The best of every lag still finds something: over the shortest overlaps (20 s of
    // smooth signals, the lags near +-280 s) up to 0.46 for these seeds; over 200 s and
    // more, 0.12 at most. A match correlates above 0.9 (above).
    const survey::ClockFit f = survey::fit_clock_offset(a, b);
    EXPECT_LT(f.correlation, 0.6) << "at " << f.offset << " s";
    const survey::ClockFit g = survey::fit_clock_offset(a, b, long_overlap);
    EXPECT_LT(g.correlation, 0.2) << "at " << g.offset << " s";
  }
  // And too little overlap for any lag: nothing found.
  const survey::Signal c = sampled(Wave(1), 0.0, 15.0, 0.01, 0.0, 0.3, rng);
  const survey::Signal d = sampled(Wave(1), 0.0, 15.0, 0.01, 0.0, 0.3, rng);
  EXPECT_FALSE(survey::fit_clock_offset(c, d).found);
}

TEST(SurveyClock, SearchIsLimitedToTheWindow) {
  const Wave w(3);
  std::mt19937 rng(3);
  const survey::Signal a = sampled(w, 0.0, 200.0, 0.01, 0.0, 0.1, rng);
  const survey::Signal b = sampled(w, 0.0, 200.0, 0.01, 25.0, 0.1, rng);
  survey::ClockOptions o;
  o.search_lo = -2.0;
  o.search_hi = 2.0;
  const survey::ClockFit near = survey::fit_clock_offset(a, b, o);
  ASSERT_TRUE(near.found);
  EXPECT_LE(std::abs(near.offset), 2.0 + 0.05);
  EXPECT_LT(near.correlation, 0.5);
  o.search_lo = 20.0;
  o.search_hi = 30.0;
  const survey::ClockFit there = survey::fit_clock_offset(a, b, o);
  ASSERT_TRUE(there.found);
  EXPECT_NEAR(there.offset, 25.0, std::max(2.0 * there.sigma, 0.002));
}

// ------------------------------------------------------------------ 10. a reference's clock

TEST_F(Survey, ReferenceTrackInAnotherTimeUnitIsFitted) {
  const Manifest m = manifest(data());
  std::vector<survey::Series> series;
  for (const auto& in : survey::survey_inputs(m, kModules)) series.push_back(survey::read_series(in.name, in.file, in.read));
  const survey::DatasetSurvey s = survey::survey_series(series);
  const TruthData truth = read_truth(data() / "GINS.bin");
  // A 10 Hz track whose time column counts `unit` seconds from 12.34 s before the data:
  // column = (t - start) / unit, so the IMUs' clock = unit * column + start.
  const double start = truth.records.front().t - 12.34;
  // The common clock is the body's: its stamps are the true times less its clock offset.
  const double expected = start - sim_->module(kBody).time_offset;
  std::vector<double> offsets;
  for (const double unit : {1.0, 0.1, 0.001}) {
    SCOPED_TRACE("unit " + std::to_string(unit) + " s");
    std::vector<TruthRecord> track;
    for (std::size_t k = 0; k < truth.records.size(); k += 20) {
      TruthRecord r = truth.records[k];
      r.t = (r.t - start) / unit;
      track.push_back(r);
    }
    const survey::ReferenceClockFit fit = survey::fit_reference_clock(track, series, s);
    std::string notes;
    for (const auto& n : fit.notes) notes += n + "\n";
    SCOPED_TRACE(notes);
    ASSERT_TRUE(fit.found);
    EXPECT_NEAR(fit.scale, unit, 1e-12 * unit);
    EXPECT_GT(fit.correlation, 0.95);
    EXPECT_LT(fit.sigma, 0.1);
    // The wheels' speed leads the track's by about slip x speed (0.04 s^2/m x 1.4 m/s): the
    // fit is some 45 ms early, inside its 3 sigma (56 ms).
    EXPECT_NEAR(fit.offset, expected, 3.0 * fit.sigma) << "sigma " << fit.sigma;
    offsets.push_back(fit.offset);
  }
  // The unit changes nothing else.
  ASSERT_EQ(offsets.size(), 3u);
  EXPECT_NEAR(offsets[1], offsets[0], 0.002);
  EXPECT_NEAR(offsets[2], offsets[0], 0.002);
}

// ------------------------------------------------------------------ 11. tables imported

/// `records`' horizontal positions at time t (linear between records).
Vec3 position_at(const std::vector<TrajectoryRecord>& records, double t) {
  auto it = std::lower_bound(records.begin(), records.end(), t,
                             [](const TrajectoryRecord& r, double x) { return r.t < x; });
  if (it == records.begin()) return records.front().p_inN;
  if (it == records.end()) return records.back().p_inN;
  const TrajectoryRecord& b = *it;
  const TrajectoryRecord& a = *(it - 1);
  const double u = (t - a.t) / (b.t - a.t);
  return (1.0 - u) * a.p_inN + u * b.p_inN;
}

TEST_F(Survey, VendorTablesImportToAManifestThatRuns) {
  // The three modules as CSV tables: the left wheel's IMU mounted with its y axis along the
  // axle ((x, y, z) -> (z, x, y)), the right wheel's clock 5 s late.
  const fs::path d = *dir_ / "tables";
  fs::remove_all(d);
  fs::create_directories(d);
  Mat3 to_y = Mat3::Zero();
  to_y(0, 2) = to_y(1, 0) = to_y(2, 1) = 1.0;
  write_table(imu_file(data(), kLeft), d / "left-C1.csv", to_y, 0.0);
  write_table(imu_file(data(), kRight), d / "right-C1.csv", Mat3::Identity(), 5.0);
  write_table(imu_file(data(), kBody), d / "body-C1.csv", Mat3::Identity(), 0.0);
  const std::string tables = "'" + (d / "left-C1.csv").string() + "' '" + (d / "right-C1.csv").string() + "' '" +
                             (d / "body-C1.csv").string() + "'";

  // What the data say, drafted (typical robot values where they cannot tell).
  {
    const CmdResult r = wheelins_cli("import " + tables + " --preset csv --vehicle-type robot -q --out '" +
                                         (d / "drafted").string() + "'", d);
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const Manifest m = manifest(d / "drafted");
    SCOPED_TRACE(r.out);
    ASSERT_EQ(m.modules.size(), 3u);
    const ModuleSpec& l = *m.find("left-C1");
    const ModuleSpec& rt = *m.find("right-C1");
    const ModuleSpec& b = *m.find("body-C1");
    EXPECT_EQ(l.kind, ModuleKind::kWheel);
    EXPECT_EQ(rt.kind, ModuleKind::kWheel);
    EXPECT_EQ(b.kind, ModuleKind::kBody);
    EXPECT_EQ(l.axle_axis, 1);
    EXPECT_EQ(rt.axle_axis, 0);
    EXPECT_EQ(l.axle_sign, 1);
    EXPECT_EQ(rt.axle_sign, 1);
    EXPECT_LT(l.p_inV.y(), 0.0);
    EXPECT_GT(rt.p_inV.y(), 0.0);
    EXPECT_EQ(b.time_offset, 0.0);  // the reference clock
    EXPECT_NEAR(l.time_offset, true_offset(kLeft), 0.05);
    EXPECT_NEAR(rt.time_offset, -5.0 + true_offset(kRight), 0.05);
    // The body's mounting from its up axis and its accelerations.
    const Mat3 C_true = dcm_from_euler(sim_->module(kBody).truth.mounting_rpy);
    const Mat3 C_drafted = dcm_from_euler(b.mounting_rpy);
    EXPECT_LT(Eigen::AngleAxisd(C_true.transpose() * C_drafted).angle() / kDeg, 3.0)
        << "drafted mounting_deg " << (b.mounting_rpy / kDeg).transpose();
    EXPECT_GE(m.static_start, sim_->start_time() - 0.01);
    EXPECT_GT(m.static_end - m.static_start, 4.0);
  }

  // With a calibrated manifest of the same vehicle for what the data cannot tell (radii,
  // positions, mountings), the drafted manifest runs like the original.
  const CmdResult imp = wheelins_cli("import " + tables + " --preset csv -q --vehicle '" +
                                         (data() / "manifest.yaml").string() + "' --out '" + (d / "dataset").string() + "'", d);
  ASSERT_EQ(imp.code, 0) << imp.out << imp.err;
  const CmdResult run = wheelins_cli("run -q -m '" + (d / "dataset" / "manifest.yaml").string() +
                                         "' -c triple --formats csv --out '" + (d / "run").string() + "'", d);
  ASSERT_EQ(run.code, 0) << run.out << run.err;
  const CmdResult ref = wheelins_cli("run -q -m '" + (data() / "manifest.yaml").string() +
                                         "' -c triple --formats csv --no-evaluate --out '" + (d / "run-original").string() + "'", d);
  ASSERT_EQ(ref.code, 0) << ref.out << ref.err;
  const std::vector<TrajectoryRecord> got = read_trajectory(d / "run" / "trajectory.csv").records;
  const std::vector<TrajectoryRecord> want = read_trajectory(d / "run-original" / "trajectory.csv").records;
  ASSERT_GT(got.size(), 100u);
  ASSERT_GT(want.size(), 100u);
  // The drafted manifest knows no heading (a local frame, heading 0) and no place (0, 0, 0):
  // the tracks agree after a turn about the vertical, which is the original's heading.
  double sxy = 0.0, sxx = 0.0;
  for (const TrajectoryRecord& w : want) {
    const Vec3 g = position_at(got, w.t);
    sxx += w.p_inN.x() * g.x() + w.p_inN.y() * g.y();
    sxy += w.p_inN.x() * g.y() - w.p_inN.y() * g.x();
  }
  const double turn = std::atan2(sxy, sxx);
  EXPECT_NEAR(-turn / kDeg, manifest(data()).initial_heading / kDeg, 1.0);
  const Eigen::Rotation2Dd R(turn);
  double worst = 0.0, length = 0.0;
  for (std::size_t k = 0; k < want.size(); ++k) {
    if (want[k].t < got.front().t || want[k].t > got.back().t) continue;
    const Vec3 g = position_at(got, want[k].t);
    worst = std::max(worst, (R * want[k].p_inN.head<2>() - g.head<2>()).norm());
    if (k > 0) length += (want[k].p_inN - want[k - 1].p_inN).norm();
  }
  // What may differ: the clocks (the fits within 30 ms: 4.5 cm at 1.5 m/s), the static
  // period (a few tenths of a second shorter; the vehicle rests longer), and the placeholder
  // place: at 0 deg latitude the run takes the earth's rotation about the vertical as 0
  // instead of 3.7e-5 rad/s, a heading error growing to 0.19 deg over the 90 s, at most
  // 0.17 m over the 105 m after the best turn. 0.25 m in all; 6 cm here.
  EXPECT_GT(length, 80.0);
  EXPECT_LT(worst, 0.25) << "over " << length << " m";
}

TEST_F(Survey, VendorTablesImportWithAReferenceTrack) {
  const fs::path d = *dir_ / "tables-truth";
  fs::remove_all(d);
  fs::create_directories(d);
  for (int g : {kLeft, kRight, kBody})
    write_table(imu_file(data(), g), d / "tables" / (kModules[g] + ".csv"), Mat3::Identity(), 0.0);
  const CmdResult r = wheelins_cli("import '" + (d / "tables").string() + "' --preset csv -q --truth '" + (data() / "GINS.bin").string() +
                                       "' --out '" + (d / "dataset").string() + "'", d);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const Manifest m = manifest(d / "dataset");
  ASSERT_TRUE(m.truth_file.has_value()) << "the import drafted no truth";
  // The track's clock against the wheels' (the slip makes the wheels lead by some 45 ms).
  EXPECT_TRUE(fs::exists(m.resolve(*m.truth_file)));
  EXPECT_NEAR(m.truth_time_offset, -sim_->module(kBody).time_offset, 0.1);
  const TruthData truth = read_truth(data() / "GINS.bin");
  EXPECT_NEAR(m.origin.lat, truth.records.front().lla.lat, 1e-6);
  EXPECT_NEAR(m.origin.lon, truth.records.front().lla.lon, 1e-6);
}

}  // namespace
