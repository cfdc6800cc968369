// The Wheel-IMU installation calibration (calib/installation_calibration.hpp,
// run/calibration.hpp): synthetic spins with known geometry (the algebra, what is and is
// not observable), and a short simulated run with the field profile's calibration
// residuals (convergence from the manifest's wrong values to the truth within 3 sigma,
// and the navigation that follows).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/calib/installation_calibration.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/run/calibration.hpp"
#include "wheelins/run/input_checks.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

/// A wheel spinning about the b x-axis of its true frame at rate omega(t) (negative:
/// rolling forward for axle_sign 1), with gravity and a forward acceleration turning with
/// it, sampled in a sensor frame rotated from the true b-frame by `true_mounting`.
struct SyntheticWheel {
  Vec3 true_mounting = Vec3(0.0, 0.6, -0.8) * kDeg;
  Vec3 lever_arm = Vec3(0.015, -0.004, 0.006);
  Vec3 accel_bias = Vec3(0.02, -0.03, 0.01);
  Vec3 gyro_bias = Vec3(1e-3, -2e-3, 5e-4);
  double radius = 0.1;
  double accel_noise = 0.05;  ///< white, per sample [m/s^2]
  bool varying_speed = true;
  double gap_start = -1.0, gap_end = -1.0;  ///< no samples in (gap_start, gap_end] [s]

  double omega(double t) const {
    if (t < 30.0) return 0.0;  // static
    const double base = -12.0;
    return varying_speed ? base + 4.0 * std::sin(2.0 * kPi * (t - 30.0) / 23.0) *
                                      std::min(1.0, (t - 30.0) / 5.0)
                         : base;
  }

  /// Samples at 200 Hz over [0, duration] into `cal`.
  void feed(WheelImuCalibrator& cal, double duration, unsigned seed = 1) const {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    const Mat3 C_StoB = dcm_from_euler(true_mounting);
    const double dt = 1.0 / 200.0;
    double theta = 0.3;
    double t_prev = 0.0;
    for (double t = dt; t <= duration + 1e-9; t += dt) {
      // Mid-interval values (fine enough at 200 Hz for this test).
      const double tm = t - 0.5 * dt;
      const double w = omega(tm);
      const double a = (omega(tm + 1e-4) - omega(tm - 1e-4)) / 2e-4;
      theta += w * dt;
      const Vec3 w_b(w, 0.0, 0.0);
      // Specific force of the IMU point in b: -g and the wheel-centre's forward
      // acceleration, both turning with the wheel, plus the centripetal and tangential
      // terms of the IMU's offset r = -l from the centre.
      const Vec3 g_dir(0.0, std::sin(theta), std::cos(theta));
      const Vec3 fwd(0.0, std::cos(theta), -std::sin(theta));
      const double a_fwd = -radius * a;
      const Vec3 r = -lever_arm;
      const Vec3 f_b = -9.8 * g_dir + a_fwd * fwd + Vec3(a, 0, 0).cross(r) + w_b.cross(w_b.cross(r));
      const Vec3 noise(n(rng), n(rng), n(rng));
      if (t > gap_start && t <= gap_end) continue;  // lost: the next sample spans the gap
      ImuSample s;
      s.t = t;
      s.dt = t - t_prev;
      s.dtheta = (C_StoB.transpose() * w_b + gyro_bias) * s.dt;
      s.dvel = (C_StoB.transpose() * f_b + accel_bias + accel_noise * noise) * s.dt;
      t_prev = t;
      cal.add(s);
    }
  }
};

ImuModule manifest_module(const SyntheticWheel& w) {
  ImuModule m;
  m.name = "wheel";
  m.kind = ModuleKind::kWheel;
  m.mounting_rpy = w.true_mounting + Vec3(0.2, -0.3, 0.35) * kDeg;  // the residuals
  m.lever_arm_inB = w.lever_arm + Vec3(0.002, 0.003, -0.003);
  m.wheel_radius = w.radius;
  return m;
}

/// The true axle and lever arm in the frame the estimate is expressed in (the corrected
/// b-frame, whose roll about the axle is the manifest's).
struct TruthInEstimateFrame {
  double tilt_y, tilt_z;  ///< remaining axle tilt [rad]
  Vec3 lever_arm;
};
TruthInEstimateFrame truth_in(const WheelImuCalibration& c, const Vec3& true_mounting, const Vec3& l) {
  const Mat3 M = dcm_from_euler(c.mounting_rpy) * dcm_from_euler(true_mounting).transpose();
  const Vec3 a = M * Vec3::UnitX();
  return {a.z(), -a.y(), M * l};
}

}  // namespace

TEST(InstallationCalibration, SyntheticWheelConvergesFromTheManifestsWrongValues) {
  SyntheticWheel w;
  const ImuModule m = manifest_module(w);
  WheelImuCalibrator cal(m, 0.0, 30.0);
  w.feed(cal, 330.0);
  const WheelImuCalibration c = cal.result();
  EXPECT_GT(c.turns, 400);
  ASSERT_TRUE(c.axle_tilt_y.observed && c.axle_tilt_z.observed);
  ASSERT_TRUE(c.lever_arm[1].observed && c.lever_arm[2].observed);
  EXPECT_FALSE(c.lever_arm[0].observed);
  const TruthInEstimateFrame t = truth_in(c, w.true_mounting, w.lever_arm);
  // The axle: the manifest was 0.46 deg off.
  EXPECT_LT(std::abs(t.tilt_y), 3.0 * c.axle_tilt_y.std);
  EXPECT_LT(std::abs(t.tilt_z), 3.0 * c.axle_tilt_z.std);
  EXPECT_LT(std::hypot(t.tilt_y, t.tilt_z), 0.02 * kDeg);
  // The lever arm: the manifest was 4.2 mm off across the axle.
  for (int i : {1, 2}) {
    EXPECT_LT(std::abs(c.lever_arm[i].value - t.lever_arm[i]), 3.0 * c.lever_arm[i].std) << i;
    EXPECT_LT(std::abs(c.lever_arm[i].value - t.lever_arm[i]), 1e-4) << i;
  }
  // Along the axle: unobservable, the manifest's value and the prior sigma.
  EXPECT_DOUBLE_EQ(c.lever_arm[0].std, InstallationCalibrationOptions{}.lever_arm_prior_std);
}

// Issue 33, 3: times in milliseconds after the static period put the data 1e8 s later; the
// rate and yaw bins were a dense vector over the time span (7 GB). Only bins with data are
// kept: memory in proportion to the samples, whatever the span.
TEST(InstallationCalibration, BinsGrowWithTheDataNotTheTimeSpan) {
  SyntheticWheel w;
  const ImuModule m = manifest_module(w);
  WheelImuCalibrator wheel(m, 0.0, 30.0);
  ImuModule body_module = m;
  body_module.kind = ModuleKind::kBody;
  BodyImuCalibrator body(body_module, 0.0, 30.0);
  ImuSample s;
  s.dt = 0.005;
  s.dvel = Vec3(0, 0, -9.8) * s.dt;
  for (int k = 1; k <= 30 * 200; ++k) {  // the static period
    s.t = k * s.dt;
    wheel.add(s);
    body.add(s);
  }
  s.dtheta = Vec3(1.0, 0, 0) * s.dt;
  for (int k = 0; k < 2000; ++k) {  // 10 s of data 1e8 s on
    s.t = 1e8 + k * s.dt;
    wheel.add(s);
    body.add(s);
  }
  EXPECT_LE(wheel.rate_bins().entries().size(), 11u);   // 1 s bins
  EXPECT_LE(wheel.axle_bins().entries().size(), 101u);  // 0.1 s bins
  EXPECT_LE(body.bins().entries().size(), 101u);
  EXPECT_GT(wheel.rate_bins().end_index(), 1e7);  // the span they stand for
  const WheelImuCalibration c = wheel.result();
  EXPECT_EQ(c.module, "wheel");
}

TEST(InstallationCalibration, AGapInTheDataDropsTheTurnItFallsIn) {
  // A 2 s dropout at speed: the sample after it spans ~4 turns with one reading; counted,
  // it would bias the lever arm by ~0.2 mm.
  SyntheticWheel w;
  w.gap_start = 100.0;
  w.gap_end = 102.0;
  const ImuModule m = manifest_module(w);
  WheelImuCalibrator cal(m, 0.0, 30.0);
  w.feed(cal, 330.0);
  const WheelImuCalibration c = cal.result();
  const TruthInEstimateFrame t = truth_in(c, w.true_mounting, w.lever_arm);
  for (int i : {1, 2}) {
    EXPECT_LT(std::abs(c.lever_arm[i].value - t.lever_arm[i]), 3.0 * c.lever_arm[i].std) << i;
    EXPECT_LT(std::abs(c.lever_arm[i].value - t.lever_arm[i]), 1e-4) << i;
  }
}

TEST(InstallationCalibration, ConstantSpeedLeavesTheLeverArmAtItsPrior) {
  // At one spin rate the centripetal term cannot be told from the accelerometer bias: the
  // lever arm keeps the manifest's value and says so, while the axle is still observed.
  SyntheticWheel w;
  w.varying_speed = false;
  const ImuModule m = manifest_module(w);
  const InstallationCalibrationOptions opt;
  WheelImuCalibrator cal(m, 0.0, 30.0, opt);
  w.feed(cal, 330.0);
  const WheelImuCalibration c = cal.result();
  EXPECT_TRUE(c.axle_tilt_y.observed && c.axle_tilt_z.observed);
  for (int i : {1, 2}) {
    EXPECT_FALSE(c.lever_arm[i].observed) << i;
    EXPECT_GT(c.lever_arm[i].std, 0.5 * opt.lever_arm_prior_std) << i;
  }
}

TEST(InstallationCalibration, TooFewTurnsEstimateNothing) {
  SyntheticWheel w;
  const ImuModule m = manifest_module(w);
  WheelImuCalibrator cal(m, 0.0, 30.0);
  w.feed(cal, 31.5);  // 1.5 s of rolling: under 20 turns
  const WheelImuCalibration c = cal.result();
  EXPECT_LT(c.turns, InstallationCalibrationOptions{}.min_turns);
  EXPECT_FALSE(c.axle_tilt_y.observed || c.axle_tilt_z.observed || c.lever_arm[1].observed ||
               c.lever_arm[2].observed);
  EXPECT_TRUE(c.mounting_rpy.isApprox(m.mounting_rpy, 1e-12));
  EXPECT_TRUE(c.lever_arm_inB().isApprox(m.lever_arm_inB, 1e-12));
  EXPECT_DOUBLE_EQ(c.axle_tilt_y.std, InstallationCalibrationOptions{}.mounting_prior_std);
}

namespace {

class SimulatedCalibration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sim::SimConfig cfg;
    cfg.seed = 5;
    cfg.chips = 1;
    cfg.duration = 240.0;
    cfg.write_ideal = false;
    cfg.effects = {"calibration"};  // only the installation residuals
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("wheelins-calibration-" + std::to_string(std::random_device{}())));
    sim_ = new sim::Simulation(cfg);
    sim_->write(*dir_, true, false);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete sim_;
  }
  static fs::path* dir_;
  static sim::Simulation* sim_;
};
fs::path* SimulatedCalibration::dir_ = nullptr;
sim::Simulation* SimulatedCalibration::sim_ = nullptr;

}  // namespace

namespace {

/// The two Wheel-IMUs of a simulated dataset calibrated: axle and lever arm within 3 sigma of
/// the truth the simulator used, and at least ten times nearer to it than the manifest.
void expect_wheels_reach_the_truth(const fs::path& dir, const sim::Simulation& sim) {
  const Manifest m = load_manifest(dir / "manifest.yaml", {});
  const std::vector<std::string> modules = configuration_modules(m, "dual-wheel", {});
  const auto cal = calibrate_installation(m, modules, {}, true, false).wheels;
  ASSERT_EQ(cal.size(), 2u);
  for (std::size_t i = 0; i < cal.size(); ++i) {
    const WheelImuCalibration& c = cal[i];
    const sim::ModuleModel& g = sim.module(static_cast<int>(i));  // left-wheel, right-wheel
    ASSERT_TRUE(c.axle_tilt_y.observed && c.axle_tilt_z.observed) << c.module;
    ASSERT_TRUE(c.lever_arm[1].observed && c.lever_arm[2].observed) << c.module;
    const TruthInEstimateFrame t = truth_in(c, g.truth.mounting_rpy, g.truth.lever_arm_inB);
    EXPECT_LT(std::abs(t.tilt_y), 3.0 * c.axle_tilt_y.std) << c.module;
    EXPECT_LT(std::abs(t.tilt_z), 3.0 * c.axle_tilt_z.std) << c.module;
    // and far nearer than the manifest was
    WheelImuCalibration as_manifest;
    as_manifest.mounting_rpy = g.manifest.mounting_rpy;
    const TruthInEstimateFrame before = truth_in(as_manifest, g.truth.mounting_rpy, g.truth.lever_arm_inB);
    EXPECT_LT(std::hypot(t.tilt_y, t.tilt_z), 0.1 * std::hypot(before.tilt_y, before.tilt_z)) << c.module;
    for (int k : {1, 2}) {
      const double err = c.lever_arm[k].value - t.lever_arm[k];
      EXPECT_LT(std::abs(err), 3.0 * c.lever_arm[k].std) << c.module << " l" << k;
      EXPECT_LT(std::abs(err), 0.1 * std::abs(g.manifest.lever_arm_inB[k] - g.truth.lever_arm_inB[k]) + 2e-5)
          << c.module << " l" << k;
    }
  }
}

}  // namespace

TEST_F(SimulatedCalibration, EstimatesReachTheTruthWithinThreeSigma) { expect_wheels_reach_the_truth(*dir_, *sim_); }

TEST(InstallationCalibration, ResidualsTenTimesTheProfilesReachTheTruthWithinThreeSigma) {
  // A manifest far off (mountings up to ~5 deg, lever arms up to ~4 cm): the estimates do not
  // depend on starting near the truth.
  sim::SimConfig cfg;
  cfg.seed = 11;
  cfg.chips = 1;
  cfg.duration = 240.0;
  cfg.write_ideal = false;
  cfg.effects = {"calibration"};
  cfg.errors.cal_lever_arm = 0.03;
  cfg.errors.cal_mounting = 3.0 * kDeg;
  const fs::path dir = fs::temp_directory_path() / ("wheelins-calibration-10x-" + std::to_string(std::random_device{}()));
  sim::Simulation sim(cfg);
  sim.write(dir, true, false);
  double worst = 0.0;  // the manifest was this far off (the test is not a trivial one)
  for (int i = 0; i < 2; ++i) worst = std::max(worst, (sim.module(i).manifest.lever_arm_inB - sim.module(i).truth.lever_arm_inB).norm());
  EXPECT_GT(worst, 0.02);
  expect_wheels_reach_the_truth(dir, sim);
  // The Body-IMU's yaw from a manifest degrees off.
  const Manifest m = load_manifest(dir / "manifest.yaml", {});
  const auto body = calibrate_installation(m, configuration_modules(m, "body-wheel", {}), {}, true, false).bodies;
  ASSERT_EQ(body.size(), 1u);
  const sim::ModuleModel& g = sim.module(2);
  const double yaw_left = (dcm_from_euler(body[0].mounting_rpy) * dcm_from_euler(g.truth.mounting_rpy).transpose())(1, 0);
  const double yaw_before = (dcm_from_euler(g.manifest.mounting_rpy) * dcm_from_euler(g.truth.mounting_rpy).transpose())(1, 0);
  ASSERT_TRUE(body[0].yaw.observed);
  EXPECT_LT(std::abs(yaw_left), 3.0 * body[0].yaw.std) << yaw_left / kDeg;
  EXPECT_GT(std::abs(yaw_before), 0.5 * kDeg);
  EXPECT_LT(std::abs(yaw_left), 0.33 * std::abs(yaw_before)) << yaw_left / kDeg << " vs " << yaw_before / kDeg;
  std::error_code ec;
  fs::remove_all(dir, ec);
}

TEST_F(SimulatedCalibration, RelativeRadiusReachesTheTruthWithinThreeSigma) {
  // Two wheels: their radii relative to each other (the mean of the two is the manifest's).
  const Manifest m = load_manifest(*dir_ / "manifest.yaml", {});
  const auto cal = calibrate_installation(m, configuration_modules(m, "dual-wheel", {}), {}, true, false).wheels;
  ASSERT_EQ(cal.size(), 2u);
  double eps[2], eps_man[2];
  for (int i = 0; i < 2; ++i) {
    const sim::ModuleModel& g = sim_->module(i);
    eps[i] = cal[i].wheel_radius.value / g.radius_manifest - 1.0;  // the estimate's share
    eps_man[i] = g.radius / g.radius_manifest - 1.0;               // the truth's
  }
  const double mean = 0.5 * (eps_man[0] + eps_man[1]);
  for (int i = 0; i < 2; ++i) {
    const WheelImuCalibration& c = cal[i];
    ASSERT_TRUE(c.wheel_radius.observed) << c.module;
    const double sigma = c.wheel_radius.std / sim_->module(i).radius_manifest;
    const double target = eps_man[i] - mean;
    EXPECT_LT(std::abs(eps[i] - target), 3.0 * sigma) << c.module << " " << eps[i] << " vs " << target;
    EXPECT_LT(std::abs(eps[i] - target), 0.1 * std::abs(target) + 2e-5) << c.module;
  }
  // One wheel alone: nothing to compare its speed with; the manifest's radius, not observed.
  const auto one = calibrate_installation(m, {cal[0].module}, {}, true, false).wheels;
  ASSERT_EQ(one.size(), 1u);
  EXPECT_FALSE(one[0].wheel_radius.observed);
  EXPECT_EQ(one[0].wheel_radius.value, m.find(cal[0].module)->wheel_radius);
}

TEST_F(SimulatedCalibration, BodyImuMountingReachesTheTruthWithinThreeSigma) {
  const Manifest m = load_manifest(*dir_ / "manifest.yaml", {});
  const auto cal = calibrate_installation(m, configuration_modules(m, "body-wheel", {}), {}, true, false);
  ASSERT_EQ(cal.bodies.size(), 1u);
  const BodyImuCalibration& c = cal.bodies[0];
  const sim::ModuleModel& g = sim_->module(2);  // body
  ASSERT_TRUE(c.tilt_x.observed && c.tilt_y.observed);
  // The vehicle z-axis as the estimate puts it, against the truth's, in the v-frame the
  // estimate defines: what is left is a tilt about v x and v y.
  const Mat3 M = dcm_from_euler(c.mounting_rpy) * dcm_from_euler(g.truth.mounting_rpy).transpose();
  const Vec3 z = M * Vec3::UnitZ();
  const Mat3 M0 = dcm_from_euler(g.manifest.mounting_rpy) * dcm_from_euler(g.truth.mounting_rpy).transpose();
  const Vec3 z0 = M0 * Vec3::UnitZ();
  EXPECT_LT(std::abs(z.y()), 3.0 * c.tilt_x.std) << z.transpose();
  EXPECT_LT(std::abs(z.x()), 3.0 * c.tilt_y.std) << z.transpose();
  EXPECT_LT(std::hypot(z.x(), z.y()), 0.2 * std::hypot(z0.x(), z0.y()));
  // The yaw, from the lateral specific force against the wheel's axle accelerometer: what is
  // left of M is a rotation about v z.
  ASSERT_TRUE(c.yaw.observed);
  EXPECT_LT(std::abs(M(1, 0)), 3.0 * c.yaw.std) << M(1, 0) / kDeg << " deg, sigma " << c.yaw.std / kDeg;
  // Fitted with it: the Body-IMU's position relative to the wheels (x, y), whose manifest
  // error is the body's own less the wheels' mean.
  auto offset = [&](bool truth) {
    const auto pos = [&](int i) { return truth ? sim_->module(i).truth.p_inV : sim_->module(i).manifest.p_inV; };
    return Vec3(pos(2) - 0.5 * (pos(0) + pos(1)));
  };
  const Vec3 correction = offset(true) - offset(false);
  ASSERT_TRUE(c.position_x.observed && c.position_y.observed);
  EXPECT_LT(std::abs(c.position_x.value - correction.x()), 3.0 * c.position_x.std) << correction.transpose();
  EXPECT_LT(std::abs(c.position_y.value - correction.y()), 3.0 * c.position_y.std) << correction.transpose();
  // The refined manifest carries it.
  const Manifest refined = apply_calibration(m, cal);
  const Vec3 moved = refined.find(c.module)->p_inV - m.find(c.module)->p_inV;
  EXPECT_NEAR(moved.x(), c.position_x.value, 1e-12);
  EXPECT_NEAR(moved.y(), c.position_y.value, 1e-12);
  EXPECT_EQ(moved.z(), 0.0);
  // Without a Wheel-IMU in the run nothing reads the lateral force independently: the
  // manifest's yaw, not observed.
  const auto alone = calibrate_installation(m, {c.module}, {}, true, false);
  ASSERT_EQ(alone.bodies.size(), 1u);
  EXPECT_FALSE(alone.bodies[0].yaw.observed);
  EXPECT_DOUBLE_EQ(alone.bodies[0].yaw.value, 0.0);
  EXPECT_NEAR(alone.bodies[0].mounting_rpy.z(), g.manifest.mounting_rpy.z(), 1e-5);
  EXPECT_FALSE(alone.bodies[0].position_x.observed || alone.bodies[0].position_y.observed);
  EXPECT_EQ(apply_calibration(m, alone).find(c.module)->p_inV, m.find(c.module)->p_inV);
  EXPECT_TRUE(alone.bodies[0].tilt_x.observed);  // roll and pitch need no wheel
}

TEST_F(SimulatedCalibration, TheRunUsesTheEstimatesAndWritesThem) {
  auto heading_rmse = [&](CalibrationMode mode, const fs::path& out) {
    RunRequest r;
    r.manifest = load_manifest(*dir_ / "manifest.yaml", {});
    r.modules = configuration_modules(r.manifest, "single", {});
    r.nav.earth_rotation = r.manifest.earth_rotation;
    r.calibration = mode;
    r.output_dir = out;
    r.progress = false;
    r.formats = {TrajectoryFormat::kCsv};
    TrajectoryData traj;
    traj.has_ned = traj.has_lla = traj.has_heading = traj.has_pos_std = true;
    r.on_record = [&](const TrajectoryRecord& rec) {
      if (traj.records.empty() || rec.t >= traj.records.back().t + 0.05 - 1e-9) traj.records.push_back(rec);
    };
    const RunResult res = run_navigation(r);
    EXPECT_EQ(fs::exists(out / "calibration.yaml"), mode == CalibrationMode::kEstimate);
    EXPECT_EQ(res.calibration.wheels.size(), mode == CalibrationMode::kEstimate ? 1u : 0u);
    const TruthData truth = read_truth(*dir_ / "GINS.bin");
    return eval::evaluate(truth, traj, earth::LocalFrame(r.manifest.origin)).heading_rmse;
  };
  const fs::path base = *dir_ / "runs";
  const double calibrated = heading_rmse(CalibrationMode::kEstimate, base / "estimate");
  const double manifest = heading_rmse(CalibrationMode::kManifest, base / "manifest");
  // The manifest's mounting error makes the heading swing with the wheel; calibrated, it
  // does not.
  EXPECT_LT(calibrated, 0.3 * manifest) << calibrated / kDeg << " vs " << manifest / kDeg << " deg";
}

namespace {

struct Cmd {
  int code;
  std::string err;
  std::string out;
};

Cmd run_cli(const std::string& args, const fs::path& scratch) {
  const fs::path err = scratch / "stderr.txt", out = scratch / "stdout.txt";
  const std::string cmd =
      std::string("'") + WHEELINS_BINARY + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  auto read = [](const fs::path& f) {
    std::ifstream in(f);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read(err), read(out)};
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_F(SimulatedCalibration, CalibrateCommandWritesARefinedManifestAndNeverTheInput) {
  const fs::path scratch = *dir_ / "cli";
  fs::create_directories(scratch);
  const fs::path input = *dir_ / "manifest.yaml";
  const std::string before = slurp(input);
  const fs::path refined = scratch / "refined.yaml";
  const Cmd ok = run_cli("calibrate -q -m '" + input.string() + "' --out '" + refined.string() + "'", scratch);
  ASSERT_EQ(ok.code, 0) << ok.err;
  ASSERT_TRUE(fs::exists(scratch / "refined.calibration.yaml"));

  // The refined manifest navigates with what the run's own pass estimates.
  const Manifest m = load_manifest(input, {});
  const Manifest r = load_manifest(refined, {});
  const std::vector<std::string> wheels = configuration_modules(m, "dual-wheel", {});
  const auto cal = calibrate_installation(m, wheels, {}, true, false).wheels;
  for (const auto& c : cal) {
    const ModuleSpec* s = r.find(c.module);
    ASSERT_NE(s, nullptr);
    EXPECT_LT((s->lever_arm_inB - c.lever_arm_inB()).norm(), 1e-6) << c.module;
    EXPECT_LT((s->mounting_rpy - c.mounting_rpy).norm(), 1e-6) << c.module;
    EXPECT_GT((s->lever_arm_inB - m.find(c.module)->lever_arm_inB).norm(), 1e-4) << c.module;
  }
  // Its data files still resolve from its own directory.
  EXPECT_EQ(fs::canonical(r.resolve(r.modules[0].file)), fs::canonical(m.resolve(m.modules[0].file)));

  // Nothing is overwritten unasked, and the input manifest never.
  const Cmd again = run_cli("calibrate -q -m '" + input.string() + "' --out '" + refined.string() + "'", scratch);
  EXPECT_NE(again.code, 0);
  EXPECT_NE(again.err.find("refined.yaml"), std::string::npos) << again.err;
  const Cmd onto_input =
      run_cli("calibrate -q --force -m '" + dir_->string() + "' --out '" + input.string() + "'", scratch);
  EXPECT_NE(onto_input.code, 0);
  EXPECT_NE(onto_input.err.find("input manifest"), std::string::npos) << onto_input.err;
  EXPECT_EQ(slurp(input), before);
  // A Body-IMU alone gets its roll and pitch from the turns; its yaw stays the manifest's
  // (it needs a Wheel-IMU in the run).
  const fs::path body_out = scratch / "b.yaml";
  const Cmd body = run_cli("calibrate -q -m '" + input.string() + "' --modules body-C1 --out '" +
                               body_out.string() + "'",
                           scratch);
  ASSERT_EQ(body.code, 0) << body.err;
  const Manifest b = load_manifest(body_out, {});
  const ModuleSpec* b0 = m.find("body-C1");
  const ModuleSpec* b1 = b.find("body-C1");
  ASSERT_NE(b0, nullptr);
  ASSERT_NE(b1, nullptr);
  EXPECT_GT((b1->mounting_rpy.head<2>() - b0->mounting_rpy.head<2>()).norm(), 1e-5);
  // The tilt is a rotation about the vehicle's x and y axes; composed with the manifest's
  // mounting it moves the Euler yaw only at second order (tilt squared, ~1e-6 rad here).
  EXPECT_NEAR(b1->mounting_rpy.z(), b0->mounting_rpy.z(), 1e-5);
  // Only the named module moves.
  for (const auto& s : m.modules) {
    if (s.name != "body-C1") {
      EXPECT_EQ(b.find(s.name)->mounting_rpy, s.mounting_rpy) << s.name;
    }
  }

  const Cmd unknown = run_cli("calibrate -q -m '" + input.string() + "' --modules nosuch --out '" +
                                  (scratch / "n.yaml").string() + "'",
                              scratch);
  EXPECT_NE(unknown.code, 0);
  EXPECT_NE(unknown.err.find("nosuch"), std::string::npos) << unknown.err;
  EXPECT_FALSE(fs::exists(scratch / "n.yaml"));
}

// The console table, calibration.yaml and the refined manifest say the same of every value:
// estimated, weak or kept (one list of decisions rendered three ways), the refined manifest
// holds what they say, and a TODO of the input stays where the value is still a guess (the
// absolute wheel radius, the track) and goes where the data determined it.
TEST_F(SimulatedCalibration, ConsoleCalibrationYamlAndRefinedManifestAgree) {
  const fs::path scratch = *dir_ / "agree";
  fs::create_directories(scratch);
  const Manifest m = load_manifest(*dir_ / "manifest.yaml", {});
  // The input as a draft leaves it: its guesses marked TODO.
  ManifestAnnotations todo;
  const std::vector<std::string> modules = {"left-C1", "body-C1"};  // one wheel: no relative radius
  for (std::size_t i = 0; i < m.modules.size(); ++i)
    for (const char* key : {"wheel_radius_m", "lever_arm_b_m", "mounting_deg", "position_v_m"})
      todo.comments["modules[" + std::to_string(i) + "]." + key] = "TODO: measure";
  todo.comments["vehicle.track_m"] = "TODO: measure (typical robot)";
  const fs::path input = *dir_ / "todo-manifest.yaml";
  save_manifest(m, input, todo);
  const fs::path refined = scratch / "refined.yaml";
  const Cmd c = run_cli("calibrate -q -m '" + input.string() + "' --modules left-C1,body-C1 --out '" +
                            refined.string() + "'", scratch);
  ASSERT_EQ(c.code, 0) << c.err;
  SCOPED_TRACE(c.out);

  const Manifest in = load_manifest(input, {});
  const InstallationCalibration cal = calibrate_installation(in, modules, {}, true, false);
  const std::vector<CalibrationDecision> decisions = calibration_decisions(cal);
  ASSERT_EQ(decisions.size(), 13u);  // a wheel: 3 + 3 + 1, a body: 3 + 3
  const YAML::Node yaml = YAML::LoadFile((scratch / "refined.calibration.yaml").string());
  const Manifest out = load_manifest(refined, {});
  const ManifestAnnotations notes = read_manifest_notes(refined);
  // The console: per module and key, the line's tag.
  std::map<std::string, std::string> console;  // "module key" -> "[...]"
  {
    std::istringstream lines(c.out);
    std::string line, module;
    while (std::getline(lines, line)) {
      for (const std::string& name : modules)
        if (line.rfind("  " + name + " ", 0) == 0) module = name;
      const auto open = line.rfind(" ["), close = line.rfind(']');
      if (module.empty() || open == std::string::npos || close < open) continue;
      const std::string tag = line.substr(open + 1, close - open);
      const bool body = module == "body-C1";
      const char* key = line.find("lever arm") != std::string::npos      ? "lever_arm_b_m"
                        : line.find("wheel radius") != std::string::npos ? "wheel_radius_m"
                        : line.find("position x") != std::string::npos   ? "position_v_m"
                        : line.find("mounting") != std::string::npos     ? "mounting_deg"
                                                                         : "";
      if (*key) console[module + " " + key] = tag;
      (void)body;
    }
  }
  const char* const angles[3] = {"roll", "pitch", "yaw"};
  const char* const axes[3] = {"x", "y", "z"};
  std::set<CalibrationOutcome> seen;
  for (const CalibrationDecision& d : decisions) {
    SCOPED_TRACE(d.module + " " + d.key + " " + std::to_string(d.component));
    seen.insert(d.outcome);
    const std::string word = to_string(d.outcome);
    // calibration.yaml
    const YAML::Node o = yaml["modules"][d.module][d.key]["outcome"];
    ASSERT_TRUE(o) << "no outcome in calibration.yaml";
    EXPECT_EQ((d.component < 0 ? o : o[d.component]).as<std::string>(), word);
    const YAML::Node est = yaml["modules"][d.module][d.key]["estimate"];
    const YAML::Node man = yaml["modules"][d.module][d.key]["manifest"];
    // The console: the whole key's tag, or this part's word in it.
    const std::string tag = console[d.module + " " + d.key];
    const std::string name = d.component < 0 ? "" : (d.key == "mounting_deg" ? angles : axes)[d.component];
    EXPECT_TRUE(tag == "[" + word + "]" || tag.find(name + ": " + word) != std::string::npos) << tag;
    // The refined manifest holds what they say: the estimate, or the manifest's value.
    const ModuleSpec& r = *out.find(d.module);
    const double held = d.key == "wheel_radius_m"  ? r.wheel_radius
                        : d.key == "lever_arm_b_m" ? r.lever_arm_inB[d.component]
                        : d.key == "position_v_m"  ? r.p_inV[d.component]
                                                   : r.mounting_rpy[d.component] / kDeg;
    // The refined manifest holds calibration.yaml's estimate column; a kept part's estimate
    // is the manifest's value (a part not estimable may be re-expressed in the calibrated
    // axes, at second order in their turn).
    const double want = (d.component < 0 ? est : est[d.component]).as<double>();
    const double manifest = (d.component < 0 ? man : man[d.component]).as<double>();
    EXPECT_NEAR(held, want, 1e-5 * std::max(1.0, std::abs(want)));
    if (d.outcome == CalibrationOutcome::kKept) {
      EXPECT_NEAR(held, manifest, 1e-5 * std::max(1.0, std::abs(manifest)));
    }
    if (d.outcome == CalibrationOutcome::kNotEstimable) {
      EXPECT_NEAR(held, manifest, d.key == "mounting_deg" ? 1e-3 : 1e-4);
    }
    // Its note says the same word, and TODO while a part that matters is not estimated.
    std::size_t index = 0;
    while (out.modules[index].name != d.module) ++index;
    const std::string note = notes.comments.at("modules[" + std::to_string(index) + "]." + d.key);
    EXPECT_NE(note.find(word), std::string::npos) << note;
    if (d.outcome != CalibrationOutcome::kEstimated && !d.without_effect) {
      EXPECT_EQ(note.rfind("TODO", 0), 0u) << note;
    }
  }
  // Every key all of whose effective parts were estimated lost its TODO; the radius (relative
  // only, and here not even that) and the track kept theirs, as did the modules not calibrated.
  for (const std::string& name : modules)
    for (const char* key : {"mounting_deg", "lever_arm_b_m", "position_v_m"}) {
      bool all = true, any = false;
      for (const CalibrationDecision& d : decisions)
        if (d.module == name && d.key == key) {
          any = true;
          all = all && (d.outcome == CalibrationOutcome::kEstimated || d.without_effect);
        }
      std::size_t index = 0;
      while (out.modules[index].name != name) ++index;
      const std::string path = "modules[" + std::to_string(index) + "]." + key;
      if (any && all) {
        EXPECT_EQ(notes.comments.at(path).find("TODO"), std::string::npos) << path;
      }
    }
  std::size_t left = 0, right = 0;
  while (out.modules[left].name != "left-C1") ++left;
  while (out.modules[right].name != "right-C1") ++right;
  EXPECT_EQ(notes.comments.at("modules[" + std::to_string(left) + "].wheel_radius_m").rfind("TODO", 0), 0u);
  EXPECT_EQ(notes.comments.at("modules[" + std::to_string(right) + "].wheel_radius_m"), "TODO: measure");
  EXPECT_EQ(notes.comments.at("vehicle.track_m"), "TODO: measure (typical robot)");
  // The case is one of mixed outcomes: at least something estimated and something kept.
  EXPECT_TRUE(seen.count(CalibrationOutcome::kEstimated));
  EXPECT_TRUE(seen.count(CalibrationOutcome::kKept));
}

TEST_F(SimulatedCalibration, WarmupOfAStreamGivesTheRunsEstimatesFromItsSpan) {
  // The streaming navigator's calibration: the samples up to static end + warm-up are kept
  // and calibrated; they equal calibrate_installation() with that end, to the last digit.
  const Manifest m = load_manifest(*dir_ / "manifest.yaml", {});
  const std::vector<std::string> modules = configuration_modules(m, "triple", {});
  const double warmup = 60.0;
  CalibrationWarmup w(m, modules, {}, warmup);
  EXPECT_DOUBLE_EQ(w.end(), m.static_end + warmup);
  std::size_t kept = 0, refused = 0;
  for (std::size_t k = 0; k < modules.size(); ++k) {
    const ModuleSpec* spec = m.find(modules[k]);
    CheckedStream stream(std::make_unique<ImuFileReader>(m.resolve(spec->file), imu_read_options(*spec, {})),
                         *spec, m, true, WarningSink{});
    ImuSample s;
    while (stream.next(s)) {
      if (w.add(static_cast<int>(k), s)) {
        ++kept;
        EXPECT_LE(s.t, w.end());
      } else {
        ++refused;
        EXPECT_GT(s.t, w.end());
        break;
      }
    }
  }
  EXPECT_EQ(refused, modules.size());
  ASSERT_EQ(w.kept().size(), kept);
  EXPECT_EQ(w.kept().front().index, 0);
  EXPECT_EQ(w.kept().back().index, static_cast<int>(modules.size()) - 1);
  const InstallationCalibration from_warmup = w.result();
  const InstallationCalibration from_files = calibrate_installation(m, modules, {}, true, false, w.end());
  ASSERT_EQ(from_warmup.wheels.size(), 2u);
  ASSERT_EQ(from_warmup.bodies.size(), 1u);
  EXPECT_GT(from_warmup.wheels[0].turns, 20);
  EXPECT_EQ(calibration_yaml(from_warmup, m), calibration_yaml(from_files, m));
  // and it is not the whole run's (the span matters)
  EXPECT_NE(calibration_yaml(from_warmup, m),
            calibration_yaml(calibrate_installation(m, modules, {}, true, false), m));
  w.release();
  EXPECT_TRUE(w.kept().empty());
}
