// The noise model learned from the data and the held yaw-rate scale factors
// (fusion/noise_adaptation.hpp, docs/filter.md section 13), end to end on a simulated
// dataset that a user's manifest would get wrong: datasheet chips (scale factors
// about +-1000 ppm) on wheels whose accelerometers carry 2 m/s/sqrt(h) of vibration noise,
// navigated with a manifest that states no noise figures at all.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/sim/simulator.hpp"
#include "nav_test_util.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

constexpr double kWheelNoise = 2.0 / 60.0;  // total wheel accelerometer white noise [m/s/sqrt(s)]

fs::path scratch(const std::string& name) {
  std::random_device rd;
  const fs::path p = fs::temp_directory_path() / ("wheelins-noise-" + name + "-" + std::to_string(rd()));
  fs::create_directories(p);
  return p;
}

struct Dataset {
  fs::path dir;
  std::vector<sim::ChipModel> chips[sim::Simulation::kGroups];
  double gyro_arw = 0.0;  // the chips' true angle random walk [rad/sqrt(s)]
};

// Writes `manifest-<variant>.yaml` beside the simulator's manifest: "none" without any
// noise map, "true" with the wheel accelerometers' true white noise.
void write_variant(const fs::path& dir, const std::string& variant) {
  YAML::Node m = YAML::LoadFile((dir / "manifest.yaml").string());
  for (YAML::Node mod : m["modules"]) {
    if (variant == "none") mod.remove("noise");
    else if (mod["kind"].as<std::string>() == "wheel")
      mod["noise"]["acc_vrw_m_s_sqrt_h"] = kWheelNoise * 60.0;
  }
  std::ofstream(dir / ("manifest-" + variant + ".yaml")) << m << "\n";
}

struct Outcome {
  eval::EvalResult eval;
  ImuErrors errors;     // subsystem 0's sensor-error estimates at the end
  Mat21 covariance;     // and its covariance
  std::vector<ModuleNoiseReport> noise;
};

Outcome navigate(const fs::path& manifest_file, const std::vector<std::string>& modules,
                 NavigatorOptions nav = {}) {
  const Manifest m = load_manifest(manifest_file, {});
  nav.earth_rotation = m.earth_rotation;
  TrajectoryData traj;
  traj.has_ned = traj.has_lla = traj.has_heading = traj.has_pos_std = true;
  Navigator navigator(m, modules, nav, [&](int stream, const TrajectoryRecord& rec) {
    if (stream == 0 && (traj.records.empty() || rec.t >= traj.records.back().t + 0.05 - 1e-9))
      traj.records.push_back(rec);
  });
  test::replay(navigator, m, modules);
  navigator.finish();
  Outcome o;
  const TruthData truth = read_truth(manifest_file.parent_path() / "GINS.bin");
  o.eval = eval::evaluate(truth, traj, earth::LocalFrame(m.origin));
  o.errors = navigator.subsystem(0).ekf().errors();
  o.covariance = navigator.subsystem(0).ekf().covariance();
  for (int k = 0; k < navigator.subsystem_count(); ++k) o.noise.push_back(navigator.noise_report(k));
  return o;
}

class NoiseAdaptationEndToEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    data_ = new Dataset;
    data_->dir = scratch("datasheet");
    sim::SimConfig cfg;
    cfg.set_profile("datasheet");  // gyro and accelerometer scale factors 1000 ppm (1 sigma)
    cfg.seed = 11;
    cfg.chips = 1;
    cfg.write_ideal = false;
    // the vibration noise of the wheels on top of the chips' own 0.3 m/s/sqrt(h)
    cfg.errors.wheel_accel_noise = std::sqrt(kWheelNoise * kWheelNoise - cfg.errors.accel_vrw * cfg.errors.accel_vrw);
    cfg.effects.insert("wheel_noise");
    const sim::Simulation sim(cfg);
    sim.write(data_->dir, true, false);
    for (int g = 0; g < sim::Simulation::kGroups; ++g) data_->chips[g] = sim.chips(g);
    data_->gyro_arw = cfg.errors.gyro_arw;
    write_variant(data_->dir, "none");
    write_variant(data_->dir, "true");
  }
  static void TearDownTestSuite() {
    fs::remove_all(data_->dir);
    delete data_;
  }
  static Dataset* data_;
};
Dataset* NoiseAdaptationEndToEnd::data_ = nullptr;

}  // namespace

TEST_F(NoiseAdaptationEndToEnd, NoRunawayWithoutNoiseFigures) {
  // Issue 13's runaway case: with a manifest that states no noise figures, the scale-factor
  // estimates stay within 3 sigma of the chips' true ones (the held yaw-rate scale factors
  // at 0 with their prior sigma, which the truth must fit too), and the drift within 15 %
  // of the run given the true figures. Both wheels, 5 laps (1800 deg of turning).
  for (int g : {0, 1}) {
    const std::string module = g == 0 ? "left-C1" : "right-C1";
    SCOPED_TRACE(module);
    const Outcome none = navigate(data_->dir / "manifest-none.yaml", {module});
    const Outcome truth = navigate(data_->dir / "manifest-true.yaml", {module});
    const sim::ChipModel& chip = data_->chips[g][0];
    const Vec3 sg = chip.gyro_T.diagonal() - Vec3::Ones();
    const Vec3 sa = chip.accel_T.diagonal() - Vec3::Ones();
    const ModuleNoiseReport& rep = none.noise[0];
    for (int a = 0; a < 3; ++a) {
      const bool held = std::find(rep.held.begin(), rep.held.end(), SG + a) != rep.held.end();
      const double sigma_g = held ? rep.given.gyro_sf_std : std::sqrt(none.covariance(SG + a, SG + a));
      EXPECT_LT(std::abs(none.errors.sg(a) - sg(a)), 3.0 * sigma_g)
          << "gyro scale factor axis " << a << ": estimate " << none.errors.sg(a) * 1e6 << " ppm, truth "
          << sg(a) * 1e6 << " ppm, sigma " << sigma_g * 1e6 << (held ? " ppm (held)" : " ppm");
      const bool held_a = std::find(rep.held.begin(), rep.held.end(), SA + a) != rep.held.end();
      const double sigma_a = held_a ? rep.given.acc_sf_std : std::sqrt(none.covariance(SA + a, SA + a));
      EXPECT_LT(std::abs(none.errors.sa(a) - sa(a)), 3.0 * sigma_a)
          << "accelerometer scale factor axis " << a << ": estimate " << none.errors.sa(a) * 1e6
          << " ppm, truth " << sa(a) * 1e6 << " ppm, sigma " << sigma_a * 1e6 << (held_a ? " ppm (held)" : " ppm");
    }
    EXPECT_LT(none.eval.drift_rate, 1.15 * truth.eval.drift_rate)
        << "without noise figures " << 100 * none.eval.drift_rate << " %, with the true ones "
        << 100 * truth.eval.drift_rate << " %";
    std::printf("[ measured ] %s, datasheet chips, wheel noise 2 m/s/sqrt(h): drift %.3f %% / "
                "heading %.3f deg without noise figures, %.3f %% / %.3f deg with the true ones\n",
                module.c_str(), 100 * none.eval.drift_rate, none.eval.heading_rmse / kDeg,
                100 * truth.eval.drift_rate, truth.eval.heading_rmse / kDeg);
  }
}

TEST_F(NoiseAdaptationEndToEnd, IdentifiesTheNoiseTheManifestDoesNotState) {
  // From the static period: the gyro's white noise (the chips' 0.24 deg/sqrt(h)). In motion:
  // the wheel accelerometers' 2 m/s/sqrt(h), from the default prior (3) and from priors
  // wrong by 10x either way. With adaptation off, the given figure stays in use.
  const Outcome o = navigate(data_->dir / "manifest-none.yaml", {"left-C1", "right-C1", "body-C1"});
  ASSERT_EQ(o.noise.size(), 3u);
  for (const ModuleNoiseReport& r : o.noise) {
    SCOPED_TRACE(r.module);
    ASSERT_TRUE(r.gyro_rest.valid);
    EXPECT_NEAR(r.arw / data_->gyro_arw, 1.0, 0.25) << r.arw / kDeg * 60 << " deg/sqrt(h)";
    EXPECT_NEAR(r.arw, r.gyro_rest.white, 1e-15);
    if (!r.wheel) continue;
    EXPECT_TRUE(r.adapted);
    EXPECT_NEAR(r.vrw / kWheelNoise, 1.0, 0.35) << r.vrw * 60 << " m/s/sqrt(h)";
    EXPECT_GT(r.velocity.updates, 1000u);
    EXPECT_GT(r.velocity.mean_nis(), 1.0);
    EXPECT_LT(r.velocity.mean_nis(), 6.0);
  }
  for (double prior : {0.2, 20.0}) {
    Manifest m = load_manifest(data_->dir / "manifest-none.yaml", {});
    for (ModuleSpec& s : m.modules) {
      s.noise.acc_vrw = prior / 60.0;
      s.noise_stated |= kNoiseVrw;
    }
    const fs::path file = data_->dir / "manifest-prior.yaml";
    save_manifest(m, file);
    const Outcome p = navigate(file, {"left-C1"});
    EXPECT_NEAR(p.noise[0].vrw / kWheelNoise, 1.0, 0.35)
        << "prior " << prior << " m/s/sqrt(h): " << p.noise[0].vrw * 60 << " m/s/sqrt(h)";
    NavigatorOptions fixed;
    fixed.noise.enabled = false;
    const Outcome f = navigate(file, {"left-C1"}, fixed);
    EXPECT_FALSE(f.noise[0].adapted);
    EXPECT_DOUBLE_EQ(f.noise[0].vrw, prior / 60.0);
    EXPECT_DOUBLE_EQ(f.noise[0].given.acc_vrw, prior / 60.0);
  }
}

TEST_F(NoiseAdaptationEndToEnd, YawRateScaleFactorsByConfiguration) {
  // A Wheel-IMU's y and z gyro scale factors and the Body-IMU's along the vehicle's yaw axis
  // (the yaw-rate scale factors) and the Wheel-IMU's axle accelerometer's are not estimated
  // where nothing shows them: single Wheel-INS, Wheel-IMUs alone. Their estimates stay
  // exactly 0 and their rows of P are 0. With a Body-IMU in the position constraint (auto,
  // either filter) the yaw-rate scale factors are estimated, from the constraint alone: they
  // move, with a covariance, while the axle accelerometer's stays held. The options
  // override the choice.
  const fs::path file = data_->dir / "manifest-none.yaml";
  const Manifest m = load_manifest(file, {});
  struct Case {
    const char* configuration;
    bool centralized;
    YawScaleFactorChoice choice;
    bool from_constraint;  ///< the yaw-rate scale factors estimated from the constraint
  };
  for (const Case& c : {Case{"triple", true, YawScaleFactorChoice::kHeld, false},
                        Case{"triple", true, YawScaleFactorChoice::kAuto, true},
                        Case{"single", false, YawScaleFactorChoice::kAuto, false},
                        Case{"dual-wheel", false, YawScaleFactorChoice::kAuto, false},
                        Case{"triple", false, YawScaleFactorChoice::kHeld, false},
                        Case{"triple", false, YawScaleFactorChoice::kAuto, true},
                        Case{"body-wheel", false, YawScaleFactorChoice::kAuto, true},
                        Case{"dual-wheel", false, YawScaleFactorChoice::kFromConstraint, true},
                        Case{"dual-wheel", true, YawScaleFactorChoice::kAuto, false}}) {
    SCOPED_TRACE(std::string(c.configuration) + (c.centralized ? " centralized" : "") +
                 (c.choice == YawScaleFactorChoice::kAuto ? " auto" : " explicit"));
    const auto modules = configuration_modules(m, c.configuration, {});
    NavigatorOptions nav;
    nav.fusion.centralized = c.centralized;
    nav.yaw_scale_factors = c.choice;
    nav.earth_rotation = m.earth_rotation;
    Navigator navigator(m, modules, nav, [](int, const TrajectoryRecord&) {});
    test::replay(navigator, m, modules, m.static_end + 200.0);
    for (int k = 0; k < navigator.subsystem_count(); ++k) {
      const Subsystem& sub = navigator.subsystem(k);
      const ModuleNoiseReport rep = navigator.noise_report(k);
      const std::vector<int> yaw = rep.wheel ? std::vector<int>{SG + 1, SG + 2} : std::vector<int>{SG + 2};
      std::vector<int> held = rep.wheel ? std::vector<int>{SA + 0} : std::vector<int>{};
      if (!c.from_constraint) held.insert(held.begin(), yaw.begin(), yaw.end());
      std::sort(held.begin(), held.end());
      EXPECT_EQ(rep.held, held) << rep.module;
      const ImuErrors& e = sub.ekf().errors();
      for (int state : held) {
        EXPECT_EQ(state >= SA ? e.sa(state - SA) : e.sg(state - SG), 0.0) << rep.module << " state " << state;
        EXPECT_EQ(sub.process_noise().estimated(state), 0.0);
        if (!c.centralized) {
          EXPECT_EQ(sub.ekf().covariance().row(state).cwiseAbs().maxCoeff(), 0.0);
          EXPECT_EQ(sub.ekf().covariance().col(state).cwiseAbs().maxCoeff(), 0.0);
        }
      }
      for (int state : yaw) {
        EXPECT_EQ(sub.process_noise().velocity_gain(state), c.from_constraint ? 0.0 : 1.0) << rep.module;
        if (c.from_constraint) {
          EXPECT_NE(e.sg(state - SG), 0.0) << rep.module << ": moved by the constraint";
          EXPECT_GT(sub.ekf().covariance()(state, state), 0.0) << rep.module;
        }
      }
      if (rep.wheel) {
        EXPECT_NE(e.sg(0), 0.0) << rep.module << ": the spin axis' is estimated";
      }
    }
  }
  NavigatorOptions on;
  on.yaw_scale_factors = YawScaleFactorChoice::kEstimated;
  on.wheel.estimate_axle_accel_scale_factor = true;
  on.earth_rotation = m.earth_rotation;
  const auto modules = configuration_modules(m, "triple", {});
  Navigator navigator(m, modules, on, [](int, const TrajectoryRecord&) {});
  for (int k = 0; k < navigator.subsystem_count(); ++k) {
    EXPECT_TRUE(navigator.noise_report(k).held.empty()) << navigator.noise_report(k).module;
    EXPECT_FALSE(navigator.subsystem(k).process_noise().velocity_consider());
  }
}

TEST_F(NoiseAdaptationEndToEnd, RunWritesNoiseYaml) {
  // noise.yaml beside the trajectory: per module the given figures (and whether the manifest
  // stated them), what the static period and the motion showed, what was used.
  const fs::path out = scratch("out");
  RunRequest r;
  r.manifest = load_manifest(data_->dir / "manifest-none.yaml", {});
  r.modules = {"left-C1", "body-C1"};
  r.output_dir = out / "run";
  r.progress = false;
  const RunResult res = run_navigation(r);
  ASSERT_EQ(res.noise.size(), 2u);
  EXPECT_NE(res.noise_report.find("left-C1"), std::string::npos);
  const YAML::Node y = YAML::LoadFile((out / "run" / "noise.yaml").string());
  EXPECT_EQ(y["format"].as<std::string>(), "wheelins-noise-1");
  EXPECT_TRUE(y["adapted"].as<bool>());
  ASSERT_EQ(y["modules"].size(), 2u);
  const YAML::Node w = y["modules"][0];
  EXPECT_EQ(w["name"].as<std::string>(), "left-C1");
  EXPECT_EQ(w["kind"].as<std::string>(), "wheel");
  EXPECT_DOUBLE_EQ(w["given"]["acc_vrw_m_s_sqrt_h"].as<double>(), 3.0);  // the wheel default
  EXPECT_NEAR(w["in_motion"]["acc_vrw_m_s_sqrt_h"].as<double>(), res.noise[0].vrw * 60.0, 1e-3 * res.noise[0].vrw * 60.0);
  EXPECT_NEAR(w["used"]["gyro_arw_deg_sqrt_h"].as<double>(), res.noise[0].arw / kDeg * 60.0, 1e-3);
  EXPECT_GT(w["consistency"]["velocity"]["updates"].as<int>(), 1000);
  // Body/Wheel-INS, distributed: the yaw-rate scale factors from the constraint (13.4).
  EXPECT_EQ(w["not_estimated"].size(), 1u);
  EXPECT_EQ(w["from_constraint_only"].size(), 2u);
  EXPECT_EQ(y["modules"][1]["kind"].as<std::string>(), "body");
  EXPECT_EQ(y["modules"][1]["not_estimated"].size(), 0u);
  EXPECT_EQ(y["modules"][1]["from_constraint_only"].size(), 1u);
  // every figure a manifest line can take back
  for (const char* key : {"gyro_arw_deg_sqrt_h", "acc_vrw_m_s_sqrt_h", "gyro_bias_deg_h"})
    EXPECT_TRUE(std::isfinite(w["used"][key].as<double>())) << key;
  fs::remove_all(out);
}
