// The whole chain on simulated datasets: simulate -> run -> evaluate.
// On error-free data the filter must add no error of its own (issue: single
// Wheel-INS drift < 0.02 %, heading RMSE < 0.05 deg over the default scenario).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <random>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/sim/simulator.hpp"
#include "nav_test_util.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  std::random_device rd;
  const fs::path p = fs::temp_directory_path() / ("wheelins-e2e-" + name + "-" + std::to_string(rd()));
  fs::create_directories(p);
  return p;
}

using test::replay;

struct Outcome {
  eval::EvalResult eval;
  NavigatorStats stats;
};

// Runs `modules` of the dataset in memory (no files) and evaluates the vehicle solution.
Outcome navigate(const fs::path& dataset, const std::vector<std::string>& modules,
                 NavigatorOptions nav = {}, double duration = 0.0) {
  RunRequest r;
  r.manifest = load_manifest(dataset / "manifest.yaml", {});
  r.modules = modules;
  r.nav = nav;
  r.nav.earth_rotation = r.manifest.earth_rotation;
  r.progress = false;
  r.max_duration = duration;
  TrajectoryData traj;
  traj.has_ned = traj.has_lla = traj.has_heading = traj.has_pos_std = true;
  r.on_record = [&](const TrajectoryRecord& rec) {
    if (traj.records.empty() || rec.t >= traj.records.back().t + 0.05 - 1e-9) traj.records.push_back(rec);
  };
  const RunResult res = run_navigation(r);
  const TruthData truth = read_truth(dataset / "GINS.bin");
  return {eval::evaluate(truth, traj, earth::LocalFrame(r.manifest.origin)), res.stats};
}

class NavEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ideal_ = new fs::path(scratch("ideal"));
    sim::SimConfig cfg;
    cfg.set_profile("ideal");
    cfg.chips = 1;
    sim::Simulation(cfg).write(*ideal_, true, false);

    field_ = new fs::path(scratch("field"));
    sim::SimConfig f;  // the default `field` profile, two chips per module
    f.chips = 2;
    f.duration = 300.0;
    sim::Simulation(f).write(*field_, true, false);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*ideal_, ec);
    fs::remove_all(*field_, ec);
    delete ideal_;
    delete field_;
  }
  static fs::path* ideal_;
  static fs::path* field_;
};
fs::path* NavEndToEnd::ideal_ = nullptr;
fs::path* NavEndToEnd::field_ = nullptr;

}  // namespace

TEST_F(NavEndToEnd, IdealSingleWheelInsAddsNoError) {
  for (const char* module : {"left-C1", "right-C1"}) {
    const Outcome o = navigate(*ideal_, {module});
    SCOPED_TRACE(module);
    EXPECT_GT(o.eval.distance, 1100.0);
    EXPECT_LT(o.eval.drift_rate, 0.0002) << "drift " << 100 * o.eval.drift_rate << " %";
    EXPECT_LT(o.eval.heading_rmse, 0.05 * kDeg) << "heading RMSE " << o.eval.heading_rmse / kDeg;
    EXPECT_GT(o.eval.within_3sigma, 0.95);
    std::printf("[ measured ] %s ideal: drift %.4f %%, heading RMSE %.4f deg, max %.3f m\n", module,
                100 * o.eval.drift_rate, o.eval.heading_rmse / kDeg, o.eval.max_error);
  }
}

TEST_F(NavEndToEnd, IdealMultiImuWithOwnWheelSpeedAddsNoError) {
  const Manifest m = load_manifest(*ideal_ / "manifest.yaml", {});
  for (const char* config : {"dual-wheel", "body-wheel", "triple"})
    for (bool centralized : {false, true}) {
      NavigatorOptions nav;
      nav.fusion.speed = SpeedSharing::kOwn;
      nav.fusion.centralized = centralized;
      const Outcome o = navigate(*ideal_, configuration_modules(m, config, {}), nav, 450.0);
      SCOPED_TRACE(std::string(config) + (centralized ? " centralized" : " distributed"));
      EXPECT_GT(o.stats.position_updates, 800u);
      EXPECT_LT(o.eval.drift_rate, 0.0003) << 100 * o.eval.drift_rate << " %";
      EXPECT_LT(o.eval.heading_rmse, 0.08 * kDeg) << o.eval.heading_rmse / kDeg << " deg";
    }
}

TEST_F(NavEndToEnd, FiveImusDistributedAndCentralized) {
  // Four Wheel-IMUs (two chips on each wheel) and a Body-IMU.
  const std::vector<std::string> five{"left-C1", "left-C2", "right-C1", "right-C2", "body-C1"};
  for (bool centralized : {false, true}) {
    NavigatorOptions nav;
    nav.fusion.centralized = centralized;
    const Outcome o = navigate(*field_, five, nav);
    SCOPED_TRACE(centralized ? "centralized" : "distributed");
    EXPECT_EQ(o.stats.velocity_updates, 5 * (o.stats.velocity_updates / 5));
    EXPECT_GT(o.stats.position_updates, 5u * 250u);
    EXPECT_TRUE(std::isfinite(o.eval.drift_rate));
    EXPECT_LT(o.eval.drift_rate, 0.01) << 100 * o.eval.drift_rate << " %";
    std::printf("[ measured ] five IMUs %s (300 s field): drift %.3f %%, heading RMSE %.3f deg\n",
                centralized ? "centralized" : "distributed", 100 * o.eval.drift_rate,
                o.eval.heading_rmse / kDeg);
  }
}

TEST_F(NavEndToEnd, CovariancesStaySymmetricPositiveDefinite) {
  const Manifest m = load_manifest(*field_ / "manifest.yaml", {});
  for (bool centralized : {false, true}) {
    NavigatorOptions nav;
    nav.fusion.centralized = centralized;
    nav.earth_rotation = m.earth_rotation;
    const auto modules = configuration_modules(m, "triple", {});
    Navigator navigator(m, modules, nav, [](int, const TrajectoryRecord&) {});
    replay(navigator, m, modules);
    for (int k = 0; k < navigator.subsystem_count(); ++k) {
      const TrajectoryRecord r = navigator.vehicle_record();
      EXPECT_TRUE(r.p_std.allFinite());
      if (centralized) continue;  // the joint covariance is checked through its blocks below
      const Mat21& P = navigator.subsystem(k).ekf().covariance();
      EXPECT_LT((P - P.transpose()).cwiseAbs().maxCoeff(), 1e-12 * P.cwiseAbs().maxCoeff());
      // Held states (not estimated) have zero rows by construction.
      const Eigen::SelfAdjointEigenSolver<Mat21> es(
          estimated_block(P, navigator.subsystem(k).process_noise()));
      EXPECT_GT(es.eigenvalues().minCoeff(), 0.0) << "subsystem " << k;
    }
  }
}

TEST_F(NavEndToEnd, RunWritesFilesAndNeverOverwritesUnasked) {
  const fs::path out = scratch("out");
  RunRequest r;
  r.manifest = load_manifest(*field_ / "manifest.yaml", {});
  r.modules = configuration_modules(r.manifest, "dual-wheel", {});
  r.output_dir = out;
  r.progress = false;
  r.max_duration = 20.0;
  const RunResult first = run_navigation(r);
  // csv, tum, kml, one csv per subsystem, faults.csv, noise.yaml, calibration.yaml, weights.csv
  ASSERT_EQ(first.files.size(), 9u);
  EXPECT_TRUE(fs::exists(out / "noise.yaml"));
  EXPECT_TRUE(fs::exists(out / "calibration.yaml"));
  EXPECT_TRUE(fs::exists(out / "weights.csv"));
  // One record per constraint epoch (1 Hz) from 1 s after the start: 19 or 20 in 20 s.
  EXPECT_GE(first.weights.size(), 19u);
  EXPECT_LE(first.weights.size(), 20u);
  for (const auto& f : first.files) EXPECT_TRUE(fs::exists(f)) << f;
  const auto size = fs::file_size(out / "trajectory.csv");
  try {
    run_navigation(r);
    ADD_FAILURE() << "a second run overwrote the results";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("already holds results"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fs::file_size(out / "trajectory.csv"), size);
  r.overwrite = true;
  EXPECT_NO_THROW(run_navigation(r));
  fs::remove_all(out);
}

TEST_F(NavEndToEnd, IdealCentralizedWithMeanWheelSpeedKeepsHeading) {
  // The paper's mean wheel speed predicted as each wheel's own speed is wrong by
  // +-yaw rate x track / 2 in a turn. On error-free data the centralized filter turned that
  // into a common heading drift of all IMUs (0.67 deg RMSE triple, 0.76 deg dual, against
  // 0.06 deg distributed) until the error was counted in its measurement noise.
  const Manifest m = load_manifest(*ideal_ / "manifest.yaml", {});
  for (const char* config : {"dual-wheel", "triple"}) {
    NavigatorOptions nav;
    nav.fusion.speed = SpeedSharing::kMean;
    nav.fusion.centralized = true;
    const Outcome o = navigate(*ideal_, configuration_modules(m, config, {}), nav);
    SCOPED_TRACE(config);
    EXPECT_GT(o.eval.distance, 1100.0);
    EXPECT_LT(o.eval.heading_rmse, 0.25 * kDeg) << o.eval.heading_rmse / kDeg << " deg";
    EXPECT_LT(o.eval.drift_rate, 0.0003) << 100 * o.eval.drift_rate << " %";
    std::printf("[ measured ] %s centralized, mean speed, ideal: drift %.4f %%, heading RMSE %.3f deg\n",
                config, 100 * o.eval.drift_rate, o.eval.heading_rmse / kDeg);
  }
}

TEST_F(NavEndToEnd, CentralizedEqualsDistributedWithoutConstraint) {
  // Two Wheel-INSs on their own speeds without the position constraint share nothing, so
  // no cross-correlation arises and the joint covariance must reproduce the distributed
  // filter exactly: a check of the joint propagation and update against the per-subsystem
  // ones. (With a Body-INS they do share: its update uses the wheels' mean speed and the
  // Wheel-INSs its level, and the centralized H carries those blocks.)
  const Manifest m = load_manifest(*field_ / "manifest.yaml", {});
  const auto modules = configuration_modules(m, "dual-wheel", {});
  NavigatorOptions nav;
  nav.fusion.position_constraint = false;
  nav.fusion.speed = SpeedSharing::kOwn;
  const Outcome d = navigate(*field_, modules, nav, 120.0);
  nav.fusion.centralized = true;
  const Outcome c = navigate(*field_, modules, nav, 120.0);
  EXPECT_NEAR(c.eval.max_error, d.eval.max_error, 1e-6);
  EXPECT_NEAR(c.eval.heading_rmse, d.eval.heading_rmse, 1e-9);
  EXPECT_NEAR(c.eval.mean_nees, d.eval.mean_nees, 1e-6);
}

TEST_F(NavEndToEnd, CentralizedMeasurementJacobiansMatchFiniteDifference) {
  // The centralized filter's H (Section VI-B-2) against a finite difference of the
  // navigator's own measurement over every IMU's error state: the mean wheel speed depends
  // on every Wheel-IMU's gyro-x bias and scale factor, a Wheel-INS model on the Body-INS
  // level, and the position constraint (eq. 11) on everything eq. (7) uses. A feedback of
  // +eps e_k removes an error eps e_k, so the column is -(dz(+) - dz(-)) / (2 eps).
  const Manifest m = load_manifest(*field_ / "manifest.yaml", {});
  const auto modules = configuration_modules(m, "triple", {});
  for (SpeedSharing speed : {SpeedSharing::kMean, SpeedSharing::kOwn}) {
    NavigatorOptions nav;
    nav.fusion.centralized = true;
    nav.fusion.speed = speed;
    nav.earth_rotation = m.earth_rotation;
    Navigator navigator(m, modules, nav, [](int, const TrajectoryRecord&) {});
    replay(navigator, m, modules, m.static_end + 47.3);  // moving, in a turn
    const int N = navigator.subsystem_count();
    ASSERT_EQ(N, 3);
    const double eps = 1e-6;
    int checked = 0, cross = 0;
    for (int kind = 0; kind < 2; ++kind)
      for (int i = 0; i < N; ++i) {
        auto measure = [&](Measurement& jm) {
          if (kind == 0) navigator.velocity_measurement(i, jm);
          else navigator.position_measurement(i, jm);
        };
        Measurement m0, mp, mn;
        measure(m0);
        for (int j = 0; j < N; ++j)
          for (int k = 0; k < kStateDim; ++k) {
            StrapdownEkf& ekf = navigator.subsystem(j).ekf();
            Vec21 dx = Vec21::Zero();
            dx(k) = eps;
            ekf.feedback(dx);
            measure(mp);
            dx(k) = -2 * eps;
            ekf.feedback(dx);
            measure(mn);
            dx(k) = eps;
            ekf.feedback(dx);
            const Vec3 col = -(mp.dz - mn.dz) / (2 * eps);
            for (int r = 0; r < 3; ++r) {
              const double h = m0.H[j](r, k);
              // 1e-2 relative: the compensation (raw - b_g) / (1 + s_g) differs from the
              // linear error model by the scale factor itself (<= 1 %).
              EXPECT_NEAR(col(r), h, 1e-2 * std::abs(h) + 2e-6)
                  << (kind ? "position" : "velocity") << " of " << i << ", block " << j
                  << " H(" << r << "," << k << ")"
                  << (speed == SpeedSharing::kMean ? " mean speed" : " own speed");
              ++checked;
              if (j != i && std::abs(h) > 1e-6) ++cross;
            }
          }
      }
    EXPECT_EQ(checked, 2 * 3 * 3 * 3 * kStateDim);
    EXPECT_GT(cross, 0);
  }
}
