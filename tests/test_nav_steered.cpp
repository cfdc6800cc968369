// Steered Wheel-IMUs end to end (docs/filter.md section 16) on the simulator's car with
// Ackermann steering (preset car-steered): a front wheel alone drifts about as a rear wheel,
// also when the car starts with its wheels turned 20 deg, and the five-IMU configuration
// navigates without isolating the steered wheels; with a wheel that does not steer the
// steered ones follow the reference rather than make it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

/// The datasets of this file, removed when the test program ends.
const fs::path& scratch_root() {
  static const iotest::ScratchDir dir;
  return dir.path();
}

/// The field profile on the car with steered front wheels, one chip per module, 300 s (about
/// 1.5 km at 6 m/s), seed 3; `start_steering_deg`: the wheels turned at the start.
fs::path dataset(double start_steering_deg) {
  const fs::path dir = scratch_root() / ("car-steered-" + std::to_string(static_cast<int>(start_steering_deg)));
  if (fs::exists(dir / "manifest.yaml")) return dir;
  sim::SimConfig cfg;
  cfg.vehicle = sim::VehicleConfig::preset_named("car-steered");
  cfg.chips = 1;
  cfg.seed = 3;
  cfg.duration = 300.0;
  cfg.start_steering_deg = start_steering_deg;
  cfg.write_ideal = false;
  sim::Simulation s(cfg);
  s.write(dir, false, false);
  return dir;
}

struct Outcome {
  double drift = 0.0;  ///< drift rate [%]
  int isolations = 0;
  std::vector<WeightSummary> weights;  ///< per module, in the order given
};

Outcome navigate(const fs::path& dir, const std::vector<std::string>& modules,
                 bool steered_in_reference = false) {
  const Manifest m = load_manifest(dir / "manifest.yaml", {});
  RunRequest r;
  r.manifest = m;
  r.modules = modules;
  r.nav.fusion.steered_in_reference = steered_in_reference;
  r.progress = false;
  r.warn = [](const std::string&) {};
  eval::RunEvaluationOptions o;
  o.eval.truth_time_offset = m.truth_time_offset;
  eval::RunEvaluation e(m.resolve(*m.truth_file), m.origin, o);
  r.on_record = [&](const TrajectoryRecord& rec) { e.add(rec); };
  const RunResult res = run_navigation(r);
  Outcome out;
  out.drift = 100.0 * e.finish().drift_rate;
  out.weights = res.weight_summary;
  for (const auto& ev : res.fault_events)
    if (ev.what.find("isolated") != std::string::npos || ev.action.find("isolated") != std::string::npos)
      ++out.isolations;
  return out;
}

}  // namespace

TEST(SteeredWheels, AFrontWheelAloneDriftsAsARearWheel) {
  // The measure: a front single within 20 % of a rear single's drift on average
  // (here one seed). With the wheels turned 20 deg at the start the front wheels do not reach
  // it yet: 1.32x on this seed, 1.44x over seeds 11-14 (the note); the bound 1.6x
  // holds the start's handling (without it a front wheel starts 18-23 deg off and drifts
  // tens of times more).
  for (double start : {0.0, 20.0}) {
    const fs::path dir = dataset(start);
    const double rear = 0.5 * (navigate(dir, {"left-C1"}).drift + navigate(dir, {"right-C1"}).drift);
    const double front =
        0.5 * (navigate(dir, {"front-left-C1"}).drift + navigate(dir, {"front-right-C1"}).drift);
    EXPECT_LT(front, (start == 0.0 ? 1.2 : 1.6) * rear)
        << "start steering " << start << " deg: front " << front << " %, rear " << rear << " %";
    EXPECT_TRUE(std::isfinite(front) && front > 0.0);
  }
}

TEST(SteeredWheels, FourHubsAndTheBodyKeepTheSteeredWheels) {
  // With the wheels turned at the start the steered wheels take their start from the others'
  // heading: none is isolated for a heading off the others', and all five drift less than a
  // front wheel alone.
  const fs::path dir = dataset(20.0);
  const Outcome five = navigate(dir, {"body-C1", "left-C1", "right-C1", "front-left-C1", "front-right-C1"});
  const Outcome front = navigate(dir, {"front-right-C1"});
  EXPECT_EQ(five.isolations, 0);
  EXPECT_LT(five.drift, front.drift);
}

TEST(SteeredWheels, TheSteeredWheelsFollowWhileAnUnsteeredWheelCounts) {
  // docs/filter.md section 16: with the rear wheels counted the front ones are tied to the
  // reference of eq. (8) but have no weight in it; fusion.steered_in_reference gives them
  // theirs; without an unsteered wheel (the body and the front pair) they make it.
  const fs::path dir = dataset(0.0);
  const std::vector<std::string> five = {"body-C1", "left-C1", "right-C1", "front-left-C1", "front-right-C1"};
  const Outcome follow = navigate(dir, five);
  ASSERT_EQ(follow.weights.size(), 5u);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(follow.weights[i].mean, 1.0 / 3.0, 0.01) << five[i];
  for (int i = 0; i < 5; ++i) EXPECT_EQ(follow.weights[i].follows, i >= 3) << five[i];
  for (int i = 3; i < 5; ++i) EXPECT_EQ(follow.weights[i].max, 0.0) << five[i];
  const Outcome count = navigate(dir, five, true);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(count.weights[i].mean, 0.2, 0.01) << five[i];
    EXPECT_FALSE(count.weights[i].follows) << five[i];
  }
  const Outcome front = navigate(dir, {"body-C1", "front-left-C1", "front-right-C1"});
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(front.weights[i].mean, 1.0 / 3.0, 0.01);
  // Followers or not, the steered wheels are constrained: the five drift less than the rear
  // Triple's 1.05x and less than a front wheel alone.
  const Outcome triple = navigate(dir, {"body-C1", "left-C1", "right-C1"});
  EXPECT_LT(follow.drift, 1.05 * triple.drift) << "five " << follow.drift << " %, Triple " << triple.drift << " %";
  EXPECT_LT(follow.drift, navigate(dir, {"front-left-C1"}).drift);
}
