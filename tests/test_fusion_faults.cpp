// Sensor faults during a run (the robustness issue): each fault is injected into
// the sample stream of a short simulated field run, and the fusion is run with
// its fault handling on and off. With it on, the fault must be detected and
// reported, and the navigation error must stay near the fault-free run's; with it
// off, the same fault must visibly hurt (so each test can fail).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/fusion/navigator.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/sim/faults.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

/// Changes sample k of module `index` (sensor axes, increments); false drops it.
using Tamper = std::function<bool(int index, ImuSample& s)>;

struct Outcome {
  eval::EvalResult eval;
  NavigatorStats stats;
  std::vector<FaultEvent> events;
  std::vector<ModuleFaultStats> module_stats;
  double max_output_gap = 0.0;  ///< longest interval between vehicle records [s]
  bool covariances_ok = true;   ///< symmetric and positive definite at the end
  std::vector<WeightRecord> weights;  ///< the reference weights of eq. (8) over time
  /// Heading of each stream (0 the vehicle, 1..N the subsystems) at its records [rad].
  std::vector<std::vector<std::pair<double, double>>> headings;
  /// The heading of `stream` at the record nearest to t.
  double heading_at(int stream, double t) const {
    const auto& h = headings.at(static_cast<std::size_t>(stream));
    auto it = std::lower_bound(h.begin(), h.end(), std::make_pair(t, -1e300));
    if (it == h.end()) --it;
    return it->second;
  }
};

class FusionFaults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::random_device rd;
    dir_ = new fs::path(fs::temp_directory_path() / ("wheelins-faults-" + std::to_string(rd())));
    sim::SimConfig cfg;  // field profile
    cfg.chips = 1;
    cfg.duration = 300.0;
    sim::Simulation(cfg).write(*dir_, true, false);
    manifest_ = new Manifest(load_manifest(*dir_ / "manifest.yaml", {}));
    truth_ = new TruthData(read_truth(*dir_ / "GINS.bin"));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete manifest_;
    delete truth_;
  }

  /// Seconds after the start of navigation (the end of the static period).
  static double at(double s) { return manifest_->static_end + s; }

  static Outcome run(const std::vector<std::string>& modules, const Tamper& tamper,
                     bool handle_faults, NavigatorOptions nav = {},
                     const Manifest* manifest = nullptr) {
    const Manifest& m = manifest ? *manifest : *manifest_;
    nav.faults.enabled = handle_faults;
    nav.earth_rotation = m.earth_rotation;
    TrajectoryData traj;
    traj.has_ned = traj.has_lla = traj.has_heading = traj.has_pos_std = true;
    Outcome out;
    double last_t = -1.0;
    std::vector<double> last_sub(modules.size() + 1, -1e300);
    out.headings.resize(modules.size() + 1);
    Navigator navigator(m, modules, nav, [&](int stream, const TrajectoryRecord& rec) {
      // Every stream's times must increase (the trajectory writers refuse anything else).
      EXPECT_GT(rec.t, last_sub[stream]) << "stream " << stream;
      last_sub[stream] = rec.t;
      out.headings[static_cast<std::size_t>(stream)].emplace_back(rec.t, rec.rpy.z());
      if (stream != 0) return;
      if (last_t > 0) out.max_output_gap = std::max(out.max_output_gap, rec.t - last_t);
      last_t = rec.t;
      if (traj.records.empty() || rec.t >= traj.records.back().t + 0.05 - 1e-9)
        traj.records.push_back(rec);
    });
    std::vector<std::unique_ptr<ImuStream>> readers;
    for (const auto& name : modules) {
      const ModuleSpec* spec = m.find(name);
      readers.push_back(
          std::make_unique<ImuFileReader>(m.resolve(spec->file), imu_read_options(*spec, {})));
    }
    ImuMerger merger(std::move(readers));
    std::size_t index;
    ImuSample s;
    std::vector<double> last(modules.size(), -1.0);
    while (merger.next(index, s)) {
      if (tamper && !tamper(static_cast<int>(index), s)) continue;
      // A dropped stretch reaches the navigator as the file reader gives a gap: one sample
      // whose interval spans it (rates held over it).
      double& lt = last[index];
      if (lt > 0.0 && s.t - lt > 1.5 * s.dt) {
        const double k = (s.t - lt) / s.dt;
        s.dtheta *= k;
        s.dvel *= k;
        s.dt = s.t - lt;
      }
      lt = s.t;
      navigator.process(static_cast<int>(index), s);
    }
    navigator.finish();
    out.eval = eval::evaluate(*truth_, traj, earth::LocalFrame(m.origin));
    out.stats = navigator.stats();
    out.events = navigator.faults().events();
    out.weights = navigator.weight_history();
    for (int i = 0; i < navigator.subsystem_count(); ++i) {
      out.module_stats.push_back(navigator.faults().stats(i));
      const Mat21& P = navigator.subsystem(i).ekf().covariance();
      // Held states (not estimated) have zero rows by construction.
      const Eigen::SelfAdjointEigenSolver<Mat21> es(
          estimated_block(P, navigator.subsystem(i).process_noise()));
      out.covariances_ok &= (P - P.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * P.cwiseAbs().maxCoeff() &&
                            es.eigenvalues().minCoeff() > 0.0;
    }
    return out;
  }

  static bool has_event(const Outcome& o, const std::string& module, const std::string& what) {
    for (const auto& e : o.events)
      if (e.module == module && e.what.find(what) != std::string::npos) return true;
    return false;
  }

  static void print(const char* name, const Outcome& on, const Outcome& off, const Outcome& none) {
    std::printf(
        "[ measured ] %s: drift %.3f %% / heading RMSE %.3f deg with fault handling, %.3f %% / "
        "%.3f deg without, fault-free %.3f %% / %.3f deg; %zu events\n",
        name, 100 * on.eval.drift_rate, on.eval.heading_rmse / kDeg, 100 * off.eval.drift_rate,
        off.eval.heading_rmse / kDeg, 100 * none.eval.drift_rate, none.eval.heading_rmse / kDeg,
        on.events.size());
    for (const auto& e : on.events)
      std::printf("             t=%.2f %s: %s -> %s\n", e.t - manifest_->static_end,
                  e.module.c_str(), e.what.c_str(), e.action.c_str());
  }

  static std::vector<std::string> triple() { return configuration_modules(*manifest_, "triple", {}); }

  static fs::path* dir_;
  static Manifest* manifest_;
  static TruthData* truth_;
};
fs::path* FusionFaults::dir_ = nullptr;
Manifest* FusionFaults::manifest_ = nullptr;
TruthData* FusionFaults::truth_ = nullptr;

}  // namespace

TEST_F(FusionFaults, NoFalseAlarmsOnAFaultFreeRun) {
  for (const char* config : {"single", "dual-wheel", "body-wheel", "triple"}) {
    const Outcome o = run(configuration_modules(*manifest_, config, {}), {}, true);
    const Outcome off = run(configuration_modules(*manifest_, config, {}), {}, false);
    SCOPED_TRACE(config);
    EXPECT_TRUE(o.events.empty()) << o.events.size() << " events, first: " << o.events[0].what;
    EXPECT_DOUBLE_EQ(o.eval.drift_rate, off.eval.drift_rate);
  }
}

TEST_F(FusionFaults, OutageOfTheFirstModuleIsBridgedAndItIsTakenBack) {
  // left-C1 drives the output epochs: 40 s without its data.
  const Tamper drop = [](int i, ImuSample& s) { return !(i == 0 && s.t > at(100) && s.t < at(140)); };
  const Outcome none = run(triple(), {}, true);
  const Outcome on = run(triple(), drop, true);
  const Outcome off = run(triple(), drop, false);
  print("left-C1 outage 40 s, triple", on, off, none);
  EXPECT_TRUE(has_event(on, "left-C1", "no data after"));
  EXPECT_TRUE(has_event(on, "left-C1", "data again after a gap"));
  EXPECT_TRUE(has_event(on, "left-C1", "re-initialised"));
  EXPECT_TRUE(has_event(on, "left-C1", "probation passed"));
  EXPECT_LT(on.max_output_gap, 0.2) << "the output must go on with the others";
  EXPECT_LT(on.eval.drift_rate, 1.5 * none.eval.drift_rate + 0.0005);
  // The vehicle heading goes on through the loss of a module: the plain mean of the others
  // would jump by half of left-C1's offset from the mean of all three; with the others'
  // offsets taken out (OutputFusion::fused) what is left is left-C1's swing about its
  // 30 s mean offset.
  const double t_drop = at(100.0) + 0.3;  // out of the fusion after faults.stale_after_s
  const double jump =
      std::abs(wrap_pi(on.heading_at(0, t_drop + 0.5) - on.heading_at(0, t_drop - 0.5)) -
               wrap_pi(none.heading_at(0, t_drop + 0.5) - none.heading_at(0, t_drop - 0.5)));
  const double plain_jump = 0.5 * std::abs(wrap_pi(none.heading_at(1, t_drop) - none.heading_at(0, t_drop)));
  std::printf("[ measured ] heading step as left-C1 drops out: %.3f deg (the plain mean's: %.3f deg)\n",
              jump / kDeg, plain_jump / kDeg);
  EXPECT_LT(jump, 0.5 * plain_jump + 0.01 * kDeg);
  // What no restart can take back: while left-C1 is out, the mean of the others drifts from
  // the mean of all three by their yaw-rate scale factors' difference (read off the
  // fault-free run), and the restarted module can only start from them. The heading may
  // be worse by that much.
  auto others = [&](double t) {
    return wrap_pi(std::atan2(std::sin(none.heading_at(2, t)) + std::sin(none.heading_at(3, t)),
                              std::cos(none.heading_at(2, t)) + std::cos(none.heading_at(3, t))) -
                   none.heading_at(0, t));
  };
  const double drift_apart = std::abs(wrap_pi(others(at(140.0)) - others(at(100.0))));
  std::printf("[ measured ] the others' mean heading drifts %.3f deg from the mean of all three "
              "during the outage\n", drift_apart / kDeg);
  EXPECT_LT(on.eval.heading_rmse, 1.5 * none.eval.heading_rmse + 0.1 * kDeg + drift_apart);
  EXPECT_GT(off.eval.max_error, 3.0 * on.eval.max_error);
  EXPECT_TRUE(on.covariances_ok);

  // The centralized filter: the restarted module's cross-covariances are reset.
  NavigatorOptions cent;
  cent.fusion.centralized = true;
  const Outcome c_none = run(triple(), {}, true, cent);
  const Outcome c_on = run(triple(), drop, true, cent);
  const Outcome c_off = run(triple(), drop, false, cent);
  print("left-C1 outage 40 s, triple centralized", c_on, c_off, c_none);
  EXPECT_TRUE(has_event(c_on, "left-C1", "probation passed"));
  EXPECT_LT(c_on.eval.drift_rate, 1.5 * c_none.eval.drift_rate + 0.0005);
  EXPECT_LT(c_on.stats.covariance_not_pd, 1u);
}

TEST_F(FusionFaults, AnImuThatStopsForGoodIsLeftOut) {
  const Tamper stop = [](int i, ImuSample& s) { return !(i == 2 && s.t > at(80)); };
  const Outcome none = run(triple(), {}, true);
  const Outcome on = run(triple(), stop, true);
  const Outcome off = run(triple(), stop, false);
  print("body-C1 stops at 80 s, triple", on, off, none);
  EXPECT_TRUE(has_event(on, "body-C1", "no data after"));
  EXPECT_EQ(on.module_stats[2].restarts, 0u);
  EXPECT_LT(on.eval.drift_rate, 2.0 * none.eval.drift_rate + 0.001);
  // Without handling the fusion waits for the missing module: no update after 80 s.
  EXPECT_LT(off.stats.position_updates, on.stats.position_updates / 2);
}

TEST_F(FusionFaults, APoorChipCountsLessWithWeightsFromTheCovariance) {
  // left-C1 made a poor chip: white noise far above the others' (ARW 2 deg/sqrt(h), VRW
  // 6 m/s/sqrt(h)) and a gyro bias random walk of 60 deg/h/sqrt(h). The noise identification
  // sees it; with ReferenceWeighting::kCovariance its larger covariance gives it the least
  // weight in the reference point of eq. (8). Whether the solution is better for it is
  // not asserted: it is not, on this short run (0.238 -> 0.273 %), and the sweep of
  // docs/accuracy.md section "Reference weights" finds it mixed (which is why the weights
  // stay equal by default).
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  Vec3 bias = Vec3::Zero();
  const Tamper poor = [&](int i, ImuSample& s) {
    if (i != 0) return true;
    const double sq = std::sqrt(s.dt);
    for (int k = 0; k < 3; ++k) {
      bias[k] += 60.0 * kDeg / 3600.0 / 60.0 * sq * n01(rng);
      s.dtheta[k] += 2.0 * kDeg / 60.0 * sq * n01(rng) + bias[k] * s.dt;
      s.dvel[k] += 6.0 / 60.0 * sq * n01(rng);
    }
    return true;
  };
  NavigatorOptions cov;
  cov.fusion.weighting = ReferenceWeighting::kCovariance;
  const Outcome equal = run(triple(), poor, true);
  rng.seed(5);
  bias.setZero();
  const Outcome weighted = run(triple(), poor, true, cov);
  ASSERT_FALSE(weighted.weights.empty());
  ASSERT_EQ(equal.weights.size(), weighted.weights.size());
  const std::vector<WeightSummary> we = summarize_weights(equal.weights, 3);
  const std::vector<WeightSummary> ww = summarize_weights(weighted.weights, 3);
  std::printf("[ measured ] poor left-C1, triple: equal weights drift %.3f %% / heading %.3f deg; "
              "from the covariance %.3f %% / %.3f deg, mean weights %.3f %.3f %.3f\n",
              100 * equal.eval.drift_rate, equal.eval.heading_rmse / kDeg,
              100 * weighted.eval.drift_rate, weighted.eval.heading_rmse / kDeg, ww[0].mean,
              ww[1].mean, ww[2].mean);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(we[i].mean, 1.0 / 3.0, 1e-9) << "equal weights stay equal";
  EXPECT_LT(ww[0].mean, ww[1].mean);
  EXPECT_LT(ww[0].mean, ww[2].mean);
  EXPECT_LT(ww[0].mean, 0.3);
  for (const WeightRecord& r : weighted.weights)
    EXPECT_NEAR(r.k[0] + r.k[1] + r.k[2], 1.0, 1e-12) << "at t=" << r.t;
  EXPECT_TRUE(weighted.covariances_ok);
}

TEST_F(FusionFaults, SingleWheelInsBridgesAShortGap) {
  const std::vector<std::string> single{"left-C1"};
  const Tamper drop = [](int, ImuSample& s) { return !(s.t > at(100) && s.t < at(101)); };
  const Outcome none = run(single, {}, true);
  const Outcome on = run(single, drop, true);
  const Outcome off = run(single, drop, false);
  print("left-C1 gap 1 s, single", on, off, none);
  EXPECT_TRUE(has_event(on, "left-C1", "re-initialised"));
  EXPECT_LT(on.eval.max_error, none.eval.max_error + 2.0);
  EXPECT_GT(off.eval.max_error, 2.0 * on.eval.max_error);
}

TEST_F(FusionFaults, GyroBiasJumpOnTheBodyImuIsIsolated) {
  // 0.5 deg/s on the Body-IMU's z axis from 100 s on: its heading runs away.
  const Tamper jump = [](int i, ImuSample& s) {
    if (i == 2 && s.t > at(100)) s.dtheta.z() += 0.5 * kDeg * s.dt;
    return true;
  };
  const Outcome none = run(triple(), {}, true);
  const Outcome on = run(triple(), jump, true);
  const Outcome off = run(triple(), jump, false);
  print("body-C1 gyro z bias jump 0.5 deg/s, triple", on, off, none);
  EXPECT_TRUE(has_event(on, "body-C1", "off the others'"));
  EXPECT_LT(on.eval.heading_rmse, off.eval.heading_rmse);
  EXPECT_LT(on.eval.drift_rate, off.eval.drift_rate);
}

TEST_F(FusionFaults, StuckWheelGyroAxisIsIsolatedAndTakenBackWhenItRecovers) {
  double stuck = 0.0;
  bool have = false;
  const Tamper stick = [&](int i, ImuSample& s) {
    if (i != 1) return true;
    if (s.t > at(100) && s.t < at(130)) {
      if (!have) stuck = s.dtheta.x() / s.dt, have = true;
      s.dtheta.x() = stuck * s.dt;
    }
    return true;
  };
  const Outcome none = run(triple(), {}, true);
  const Outcome on = run(triple(), stick, true);
  have = false;
  const Outcome off = run(triple(), stick, false);
  print("right-C1 gyro x stuck 30 s, triple", on, off, none);
  EXPECT_TRUE(has_event(on, "right-C1", "slip or a lifted wheel") ||
              has_event(on, "right-C1", "velocity innovations inconsistent"));
  EXPECT_TRUE(has_event(on, "right-C1", "probation passed"));
  EXPECT_LT(on.eval.drift_rate, 0.25 * off.eval.drift_rate);
  // Without fault handling the identified noise model already holds the stuck axis to
  // 8.9 deg (33 deg with the manifest's figures fixed); the handling must still halve it
  // and stay under the 3.2 deg it reached before the noise identification.
  EXPECT_LT(on.eval.heading_rmse, 0.5 * off.eval.heading_rmse);
  EXPECT_LT(on.eval.heading_rmse, 3.3 * kDeg);
}

TEST_F(FusionFaults, WheelSlipIsDetectedAndItsSpeedNotUsed) {
  // The simulator's physical slip: the right wheel spins 50 % too fast for 4 s (ice);
  // the gyro is right about the wheel, its speed is wrong about the vehicle.
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("wheelins-slip-" + std::to_string(rd()));
  sim::SimConfig cfg;
  cfg.chips = 1;
  cfg.duration = 300.0;
  cfg.faults.push_back(sim::parse_fault_spec("slip:right-wheel:130:134:ratio=0.5"));
  sim::Simulation(cfg).write(dir, true, false);
  const Manifest m = load_manifest(dir / "manifest.yaml", {});
  const auto dual = configuration_modules(m, "dual-wheel", {});
  const Outcome none = run(dual, {}, true);
  const Outcome on = run(dual, {}, true, {}, &m);
  const Outcome off = run(dual, {}, false, {}, &m);
  print("right wheel slips (ratio 0.5) for 4 s, dual", on, off, none);
  EXPECT_GT(on.module_stats[1].speed_rejected, 0u);
  EXPECT_TRUE(has_event(on, "right-C1", "slip or a lifted wheel"));
  EXPECT_LT(on.eval.drift_rate, off.eval.drift_rate);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

TEST_F(FusionFaults, SaturatedWheelGyroIsDetectedAndBridged) {
  // The left Wheel-IMU has a 600 deg/s gyro, below its rate at cruise (825 deg/s): its
  // readings are clipped; the right one (2000 deg/s) is not.
  Manifest m = *manifest_;
  const double range = 600.0 * kDeg;
  m.modules[0].gyro_range = range;
  ASSERT_EQ(m.modules[0].name, "left-C1");
  const Tamper clip = [&](int i, ImuSample& s) {
    if (i == 0)
      for (int k = 0; k < 3; ++k) s.dtheta(k) = std::clamp(s.dtheta(k), -range * s.dt, range * s.dt);
    return true;
  };
  const auto modules = configuration_modules(m, "triple", {});
  const Outcome none = run(modules, {}, true);
  const Outcome on = run(modules, clip, true, {}, &m);
  const Outcome off = run(modules, clip, false, {}, &m);
  print("left gyro clipped at 600 deg/s, triple", on, off, none);
  EXPECT_GT(on.module_stats[0].saturated_samples, 1000u);
  EXPECT_TRUE(has_event(on, "left-C1", "gyro at full scale"));
  EXPECT_LT(on.eval.drift_rate, 0.5 * off.eval.drift_rate);
  EXPECT_TRUE(on.covariances_ok);
}

TEST(FaultMonitor, DetectorNeedsMaxFailedOfTheWindow) {
  FaultOptions o;
  o.window = 5;
  o.max_failed = 3;
  o.test_ratio = 2.0;
  FaultMonitor m({"a"}, o);
  EXPECT_FALSE(m.velocity_test(0, 5.0));
  EXPECT_FALSE(m.velocity_test(0, 1.0));
  EXPECT_FALSE(m.velocity_test(0, 5.0));
  EXPECT_FALSE(m.velocity_test(0, 1.0));
  EXPECT_TRUE(m.velocity_test(0, 5.0));   // 3 of the last 5
  EXPECT_FALSE(m.velocity_test(0, 1.0));  // the first failure left the window
  m.clear_tests(0);
  EXPECT_FALSE(m.velocity_test(0, 5.0));
  EXPECT_EQ(m.stats(0).velocity_failed, 4u);
}

TEST(FaultMonitor, ReportsTransitionsAndTimeUnused) {
  FaultMonitor m({"a", "b"}, {});
  m.transition(1, Health::kOut, 10.0, "no data", "left out");
  m.transition(1, Health::kRealign, 12.0, "data again", "re-levelling");
  m.transition(1, Health::kProbation, 12.5, "re-initialised", "probation");
  m.transition(1, Health::kOk, 22.5, "probation passed", "back");
  m.finish(30.0);
  EXPECT_DOUBLE_EQ(m.stats(1).seconds_unused, 12.5);
  EXPECT_EQ(m.events().size(), 4u);
  const std::string csv = fault_report_csv(m);
  EXPECT_NE(csv.find("10.000,b,no data,left out"), std::string::npos) << csv;
  EXPECT_NE(fault_report_text(m).find("unused 12.5 s"), std::string::npos);
}

TEST(FaultMonitor, OptionsAreValidated) {
  FaultOptions o;
  o.max_failed = 30;
  o.window = 20;
  EXPECT_THROW(FaultMonitor({"a"}, o), InputError);
  o = {};
  o.stale_after = 0.0;
  EXPECT_THROW(o.validate(), InputError);
}
