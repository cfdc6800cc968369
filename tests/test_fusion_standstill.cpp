// A standing vehicle, a reversed axle and a long outage (hardening, round 3): a short
// simulated robot run with a 120 s stop after its second lap, navigated through
// run_navigation() with the zero-velocity detection on and off, with one wheel's axle_sign
// reversed in the manifest (the data checks off), and with the data of every module
// jumping 1e9 s ahead. Each test prints its figures ([ measured ] lines).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

ModuleSpec* module(Manifest& m, const std::string& name) {
  for (auto& s : m.modules)
    if (s.name == name) return &s;
  return nullptr;
}

struct Outcome {
  eval::EvalResult eval;
  RunResult result;
  std::vector<TrajectoryRecord> records;
  std::vector<std::string> warnings;
  /// The horizontal distance the vehicle solution moved between t0 and t1 [m].
  double moved(double t0, double t1) const {
    auto at = [&](double t) {
      const TrajectoryRecord* best = &records.front();
      for (const auto& r : records)
        if (std::abs(r.t - t) < std::abs(best->t - t)) best = &r;
      return best->p_inN;
    };
    return (at(t1) - at(t0)).head<2>().norm();
  }
  bool has_event(const std::string& module, const std::string& what) const {
    for (const auto& e : result.fault_events)
      if (e.module == module && e.what.find(what) != std::string::npos) return true;
    return false;
  }
  int isolations(const std::string& module) const {
    int n = 0;
    for (const auto& e : result.fault_events) n += e.module == module && e.action.rfind("isolated:", 0) == 0;
    return n;
  }
};

class Standstill : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::random_device rd;
    data_ = std::make_unique<Data>();
    dir_ = &data_->dir;
    manifest_ = &data_->manifest;
    truth_ = &data_->truth;
    stop_ = &data_->stop;
    *dir_ = fs::temp_directory_path() / ("wheelins-standstill-" + std::to_string(rd()));
    sim::SimConfig cfg;  // field profile, robot
    cfg.chips = 1;
    cfg.rate_hz = 100.0;
    cfg.laps = 3;
    cfg.loop_scale = 0.25;  // 64 m per lap
    cfg.stop_s = 120.0;     // after lap 2: about 113 s at rest
    cfg.write_ideal = false;
    sim::Simulation(cfg).write(*dir_, true, false);
    *manifest_ = load_manifest(*dir_ / "manifest.yaml", {});
    *truth_ = read_truth(*dir_ / "GINS.bin");
    // The stop: the truth's speed below 1 mm/s, the longest such stretch after the start.
    double from = 0.0, best0 = 0.0, best1 = 0.0;
    bool in = false;
    for (const auto& r : truth_->records) {
      const bool still = r.v_ned.norm() < 1e-3 && r.t > manifest_->static_end + 10.0;
      if (still && !in) from = r.t;
      if (!still && in && r.t - from > best1 - best0) best0 = from, best1 = r.t;
      in = still;
    }
    *stop_ = {best0, best1};
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    data_.reset();
  }

  static Outcome run(const std::string& configuration, NavigatorOptions nav = {}, const Manifest* manifest = nullptr) {
    RunRequest r;
    r.manifest = manifest ? *manifest : *manifest_;
    const std::vector<std::string> chips(configuration == "single" ? 1 : configuration == "triple" ? 3 : 2, "C1");
    r.modules = configuration_modules(r.manifest, configuration, chips);
    nav.earth_rotation = r.manifest.earth_rotation;
    r.nav = nav;
    r.nav.module_records = false;
    r.calibration = CalibrationMode::kManifest;
    r.data_checks = false;
    r.progress = false;
    Outcome out;
    r.warn = [&](const std::string& w) { out.warnings.push_back(w); };
    TrajectoryData traj;
    traj.has_ned = traj.has_lla = traj.has_heading = traj.has_pos_std = true;
    r.on_record = [&](const TrajectoryRecord& rec) {
      if (traj.records.empty() || rec.t >= traj.records.back().t + 0.05 - 1e-9) traj.records.push_back(rec);
    };
    out.result = run_navigation(r);
    out.records = traj.records;
    out.eval = eval::evaluate(*truth_, traj, earth::LocalFrame(r.manifest.origin));
    return out;
  }

  /// The simulated dataset, its manifest and truth, and the stop [s, s].
  struct Data {
    fs::path dir;
    Manifest manifest;
    TruthData truth;
    std::pair<double, double> stop;
  };
  static inline std::unique_ptr<Data> data_;
  static inline fs::path* dir_ = nullptr;
  static inline Manifest* manifest_ = nullptr;
  static inline TruthData* truth_ = nullptr;
  static inline std::pair<double, double>* stop_ = nullptr;
};

}  // namespace

TEST_F(Standstill, StandingVehicleHoldsItsPlaceAndBlamesNobody) {
  const double t0 = stop_->first + 2.0, t1 = stop_->second - 0.5;
  ASSERT_GT(t1 - t0, 100.0) << "the simulated stop is too short";
  for (const char* configuration : {"single", "triple"})
    for (bool centralized : {false, true}) {
      if (centralized && std::string(configuration) == "single") continue;
      NavigatorOptions on;
      on.fusion.centralized = centralized;
      NavigatorOptions off = on;
      off.standstill.enabled = false;
      const Outcome a = run(configuration, on), b = run(configuration, off);
      std::printf("[ measured ] %s%s, %.0f s at rest: moved %.4f m with the zero-velocity detection "
                  "(%llu steps standing), %.4f m without; final error %.3f / %.3f m; fault events %zu / %zu\n",
                  configuration, centralized ? " centralized" : "", t1 - t0, a.moved(t0, t1),
                  static_cast<unsigned long long>(a.result.stats.standstill_steps), b.moved(t0, t1),
                  a.eval.final_error, b.eval.final_error, a.result.fault_events.size(),
                  b.result.fault_events.size());
      // Standing through the whole stop (and the start after the static period).
      EXPECT_GE(a.result.stats.standstill_steps, static_cast<std::uint64_t>(2.0 * (t1 - t0)));
      EXPECT_EQ(b.result.stats.standstill_steps, 0u);
      EXPECT_LT(a.moved(t0, t1), 0.02);
      EXPECT_TRUE(a.result.fault_events.empty());
      EXPECT_LT(a.eval.final_error, 1.0);
    }
}

TEST_F(Standstill, ReversedAxleIsTheWheelsFaultNotTheBodys) {
  Manifest m = *manifest_;
  ModuleSpec* left = module(m, "left-C1");
  ASSERT_NE(left, nullptr);
  left->axle_sign = -left->axle_sign;
  const Outcome clean = run("triple");
  for (const char* configuration : {"triple", "dual-wheel"}) {
    const Outcome a = run(configuration, {}, &m);
    NavigatorOptions blind;
    blind.faults.reverse_time = 1e6;  // never decided: how it was before the direction check
    const Outcome b = run(configuration, blind, &m);
    std::printf("[ measured ] %s, left axle_sign reversed: final error %.2f m, max %.2f m (without the "
                "direction check %.2f m, max %.2f m; fault-free triple %.2f m) over %.0f m\n",
                configuration, a.eval.final_error, a.eval.max_error, b.eval.final_error, b.eval.max_error,
                clean.eval.final_error, a.eval.distance);
    EXPECT_TRUE(a.has_event("left-C1", "rolls against the vehicle's motion")) << configuration;
    EXPECT_EQ(a.isolations("left-C1"), 1) << configuration;  // and never retried
    EXPECT_EQ(a.isolations("right-C1"), 0) << configuration;
    EXPECT_EQ(a.isolations("body-C1"), 0) << configuration;
    EXPECT_LT(a.eval.final_error, 1.0) << configuration;
    EXPECT_FALSE(b.has_event("left-C1", "rolls against the vehicle's motion")) << configuration;
  }
  // Alone it cannot be outvoted: it is navigated as it comes, and the run warns at the end.
  const Outcome single = run("single", {}, &m);
  bool warned = false;
  for (const auto& w : single.warnings) warned = warned || w.find("rolled backward for 100 %") != std::string::npos;
  EXPECT_TRUE(warned);
  for (const auto& w : run("single").warnings) EXPECT_EQ(w.find("rolled backward"), std::string::npos) << w;
}

TEST_F(Standstill, WheelSpinningAboutAnotherAxisIsReportedAtTheEnd) {
  Manifest m = *manifest_;
  ModuleSpec* left = module(m, "left-C1");
  ASSERT_NE(left, nullptr);
  left->axle_axis = 2;  // the data spin about the sensor's x
  const Outcome single = run("single", {}, &m);
  bool warned = false;
  for (const auto& w : single.warnings) warned = warned || w.find("about the axle the manifest gives") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST_F(Standstill, LongOutageOfEveryModuleEndsTheRunNamingTheFileAndRecord) {
  // Every module's data jump ahead after 60 s of navigation (a new copy of the files).
  const double t_jump = manifest_->static_end + 60.0;
  auto jumped = [&](double jump) {
    const fs::path dir = *dir_ / ("jump-" + std::to_string(static_cast<long long>(jump)));
    fs::create_directories(dir);
    Manifest m = *manifest_;
    for (const char* name : {"left-C1", "right-C1", "body-C1"}) {
      ModuleSpec* s = module(m, name);
      const fs::path in = manifest_->resolve(s->file), out = dir / (std::string(name) + ".bin");
      ImuFileReader reader(in, imu_read_options(*s, {}));
      ImuFileWriter writer(out, s->format, s->layout);
      ImuSample sample;
      while (reader.next(sample)) {
        ImuRow r = reader.row();
        if (r.t > t_jump) r.t += jump;
        writer.write_row(r);
      }
      writer.commit();
      s->file = out;
    }
    return m;
  };
  // An hour without data from any module: past faults.max_outage_s, the run ends.
  const Manifest far = jumped(3600.0);
  for (const char* configuration : {"single", "triple"}) {
    std::string error;
    try {
      run(configuration, {}, &far);
    } catch (const InputError& e) {
      error = e.what();
    }
    std::printf("[ measured ] %s: %s\n", configuration, error.c_str());
    EXPECT_NE(error.find("left-C1.bin"), std::string::npos) << error;
    EXPECT_NE(error.find("a gap of 3600.01 s"), std::string::npos) << error;
    EXPECT_NE(error.find("faults.max_outage_s"), std::string::npos) << error;
    EXPECT_NE(error.find("(record "), std::string::npos) << error;
  }
  // The probe's 1e9 s jump is more than a day between two records: the reader refuses it
  // before any navigation, naming the file and the record.
  const Manifest absurd = jumped(1e9);
  std::string error;
  try {
    run("single", {}, &absurd);
  } catch (const InputError& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("left-C1.bin': record "), std::string::npos) << error;
  EXPECT_NE(error.find("more than a day"), std::string::npos) << error;
  // Within the limit it is bridged.
  const Manifest near_m = jumped(5.0);
  const Outcome near = run("single", {}, &near_m);
  EXPECT_TRUE(near.has_event("left-C1", "data again after a gap of 5.0"));
  EXPECT_GT(near.records.back().t, t_jump + 5.0 + 60.0);
  std::printf("[ measured ] single, a 5 s gap of every module bridged: final error %.2f m over %.0f m\n",
              near.eval.final_error, near.eval.distance);
}
