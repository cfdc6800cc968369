// The fault handler alone (fusion/fault_handler.hpp): its hooks called directly on
// three subsystems (two Wheel-INSs and a Body-INS) aligned at rest, without a
// navigator or data files. Each test drives one rule of docs/faults.md and checks
// the health, the counters and the report it leaves.
#include <gtest/gtest.h>

#include <memory>

#include "wheelins/fusion/fault_handler.hpp"

using namespace wheelins;

namespace {

constexpr double kRate = 200.0, kDt = 1.0 / kRate, kT0 = 100.0, kG = 9.8;

/// Two Wheel-IMUs and a Body-IMU at rest on level ground, aligned at kT0, with the
/// distributed filter and the output fusion the handler acts through.
struct Rig {
  VehicleSetup setup;
  earth::LocalFrame frame{setup.origin};
  NavigatorOptions opt;
  std::unique_ptr<Subsystems> subs;
  std::unique_ptr<FilterBackend> filter;
  std::unique_ptr<OutputFusion> output;

  explicit Rig(int n_modules = 3, double gyro_range = 0.0) {
    setup.source = "rig";
    setup.gravity = kG;
    ImuModule left, right, body;
    left.name = "left";
    left.p_inV = Vec3(0.0, -0.2, 0.0);
    left.axle_sign = -1;
    left.wheel_radius = 0.1;
    left.gyro_range = gyro_range;
    right = left;
    right.name = "right";
    right.p_inV = Vec3(0.0, 0.2, 0.0);
    right.axle_sign = 1;
    body.name = "body";
    body.kind = ModuleKind::kBody;
    body.p_inV = Vec3(0.2, 0.0, -0.1);
    setup.modules = {left, right, body};
    opt.earth_rotation = false;
    std::vector<std::string> names = {"left", "right", "body"};
    names.resize(static_cast<std::size_t>(n_modules));
    subs = std::make_unique<Subsystems>(setup, names, opt);
    StaticAccumulator still;
    for (int k = 0; k < 100; ++k) still.add(rest_sample(kT0 - 0.5 + k * kDt));
    for (int i = 0; i < subs->size(); ++i) (*subs)[i].start(still, 0.0, kT0);
    filter = make_filter_backend(*subs, false);
    filter->start();
    // One epoch at rest, so that every subsystem has a rate and a wheel speed (zero).
    for (int i = 0; i < subs->size(); ++i) {
      (*subs)[i].propagate(rest_sample(kT0 + kDt));
      filter->propagated(i);
    }
    output = std::make_unique<OutputFusion>(*subs, *filter, frame, opt,
                                            [](int, const TrajectoryRecord&) {});
  }
  std::unique_ptr<FaultPolicy> policy() const {
    auto p = std::make_unique<FaultPolicy>(opt.faults, *subs, *filter, *output);
    p->on_start(kT0);
    return p;
  }
  /// A sample of an IMU at rest, level: no rotation, the specific force straight up.
  static ImuSample rest_sample(double t) {
    ImuSample s;
    s.t = t;
    s.dt = kDt;
    s.dvel = Vec3(0.0, 0.0, -kG) * kDt;
    return s;
  }
  /// Feeds a rest sample of every module in `modules` at each epoch in (t0, t1].
  static void feed(FaultHandler& h, const std::vector<int>& modules, double t0, double t1) {
    for (double t = t0 + kDt; t <= t1 + 1e-9; t += kDt)
      for (int i : modules) {
        const ImuSample s = rest_sample(t);
        ImuSample b = s;
        h.on_sample(i, s, b);
      }
  }
};

bool has_event(const FaultMonitor& m, const std::string& module, const std::string& text) {
  for (const FaultEvent& e : m.events())
    if (e.module == module && e.what.find(text) != std::string::npos) return true;
  return false;
}

UpdateReport report(double test_ratio, bool accepted = true) {
  UpdateReport r;
  r.dim = 3;
  r.test_ratio = test_ratio;
  r.accepted = accepted;
  return r;
}

}  // namespace

TEST(FaultHandler, NoFaultHandlingUsesEverySampleAndModule) {
  Rig rig;
  NoFaultHandling h({"left", "right", "body"}, rig.opt.faults);
  ImuSample s = Rig::rest_sample(kT0 + 1.0);
  s.dt = 5.0;  // a gap the policy would re-level after
  ImuSample b = s;
  EXPECT_TRUE(h.on_sample(0, s, b));
  EXPECT_EQ(b.dtheta, s.dtheta);
  SpeedSelection sel;
  sel.speed_ok[0] = sel.speed_ok[1] = true;
  const SpeedSelection before = sel;
  h.on_velocity_step(kT0 + 50.0);
  h.screen_speeds(kT0 + 50.0, {}, sel);
  EXPECT_EQ(sel.speed_ok, before.speed_ok);
  EXPECT_EQ(sel.fallback, before.fallback);
  for (int k = 0; k < 40; ++k) h.on_velocity_update(2, report(100.0, k % 2 == 0), kT0 + k);
  h.on_position_step(kT0 + 60.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(h.in_use(i) && h.counted(i) && h.tied(i)) << i;
    EXPECT_EQ(h.monitor().health(i), Health::kOk);
  }
  EXPECT_TRUE(h.monitor().events().empty());
  EXPECT_EQ(h.monitor().stats(2).velocity_rejected, 20u);  // the gate's refusals are counted
}

TEST(FaultHandler, ModuleWithoutDataGoesOutThenRealignsRestartsAndPassesProbation) {
  Rig rig;
  auto h = rig.policy();
  const FaultOptions& o = rig.opt.faults;
  // The right Wheel-IMU stops: out once its data lag the others' by stale_after.
  Rig::feed(*h, {0, 1, 2}, kT0, kT0 + 1.0);
  Rig::feed(*h, {0, 2}, kT0 + 1.0, kT0 + 1.0 + o.stale_after + 0.02);
  EXPECT_EQ(h->monitor().health(1), Health::kOut);
  EXPECT_FALSE(h->in_use(1));
  EXPECT_TRUE(has_event(h->monitor(), "right", "no data after t=101.000"));
  // It comes back: its samples re-level it (not navigated) for realign_time, then it
  // restarts from the others and is on probation: tied, not counted.
  const double back = kT0 + 3.0;
  ImuSample s = Rig::rest_sample(back);
  ImuSample b = s;
  Rig::feed(*h, {0, 2}, kT0 + 1.12, back);
  EXPECT_FALSE(h->on_sample(1, s, b));
  EXPECT_EQ(h->monitor().health(1), Health::kRealign);
  EXPECT_EQ(h->monitor().stats(1).gaps, 1u);
  Rig::feed(*h, {0, 1, 2}, back, back + o.realign_time + 0.01);
  EXPECT_EQ(h->monitor().health(1), Health::kProbation);
  EXPECT_TRUE(h->tied(1));
  EXPECT_FALSE(h->counted(1));
  EXPECT_EQ(h->monitor().stats(1).restarts, 1u);
  // The policy decided the restart at that time; the navigator's parts carry it out
  // (AidContext::act_on_faults, tested end to end by FusionFaults.*).
  const FaultActions act = h->take_actions();
  ASSERT_TRUE(act.restart.has_value());
  EXPECT_EQ(act.restart->module, 1);
  EXPECT_NEAR(act.restart->fix.t, back + o.realign_time, 0.02);
  EXPECT_FALSE(h->actions_pending());
  // Probation passes at the first velocity step probation seconds later.
  const double since = h->monitor().since(1);
  h->on_velocity_step(since + o.probation - 0.1);
  EXPECT_EQ(h->monitor().health(1), Health::kProbation);
  h->on_velocity_step(since + o.probation);
  EXPECT_EQ(h->monitor().health(1), Health::kOk);
  EXPECT_TRUE(has_event(h->monitor(), "right", "probation passed"));
}

TEST(FaultHandler, LongSampleIntervalIsAGap) {
  Rig rig;
  auto h = rig.policy();
  Rig::feed(*h, {0, 1, 2}, kT0, kT0 + 0.5);
  ImuSample s = Rig::rest_sample(kT0 + 0.5 + rig.opt.faults.max_gap + 0.01);
  s.dt = rig.opt.faults.max_gap + 0.01;
  ImuSample b = s;
  EXPECT_FALSE(h->on_sample(0, s, b));
  EXPECT_EQ(h->monitor().health(0), Health::kRealign);
  EXPECT_TRUE(has_event(h->monitor(), "left", "data again after a gap of 0.060 s"));
}

TEST(FaultHandler, DetectorIsolatesWhenOthersCanTakeOverAndOnlyReportsALoneModule) {
  const FaultOptions o;
  {
    Rig rig;
    auto h = rig.policy();
    for (int k = 1; k < o.max_failed; ++k) h->on_velocity_update(2, report(2 * o.test_ratio), kT0 + k);
    EXPECT_EQ(h->monitor().health(2), Health::kOk);
    h->on_velocity_update(2, report(2 * o.test_ratio), kT0 + o.max_failed);
    EXPECT_EQ(h->monitor().health(2), Health::kIsolated);
    EXPECT_TRUE(h->in_use(2));  // navigates alone
    EXPECT_FALSE(h->tied(2));
    EXPECT_EQ(h->monitor().stats(2).isolations, 1u);
    EXPECT_TRUE(has_event(h->monitor(), "body", "velocity innovations inconsistent"));
    // Still inconsistent while isolated (two others healthy): nothing more is said, and above
    // all not that nobody could take over.
    const std::size_t events = h->monitor().events().size();
    for (int k = 1; k <= 2 * o.max_failed; ++k)
      h->on_velocity_update(2, report(2 * o.test_ratio), kT0 + o.max_failed + 0.1 * k);
    EXPECT_EQ(h->monitor().health(2), Health::kIsolated);
    EXPECT_EQ(h->monitor().events().size(), events);
    EXPECT_EQ(h->monitor().stats(2).isolations, 1u);
    // Retried after retry_after: re-levelled, then restarted.
    h->on_velocity_step(kT0 + o.max_failed + o.retry_after);
    EXPECT_EQ(h->monitor().health(2), Health::kRealign);
  }
  {
    Rig rig(1);
    auto h = rig.policy();
    for (int k = 1; k <= 3 * o.max_failed; ++k) h->on_velocity_update(0, report(2 * o.test_ratio), kT0 + k);
    EXPECT_EQ(h->monitor().health(0), Health::kOk);
    ASSERT_EQ(h->monitor().events().size(), 1u);  // reported once
    EXPECT_NE(h->monitor().events()[0].action.find("kept"), std::string::npos);
  }
}

TEST(FaultHandler, SaturatedWheelGetsTheOtherWheelsRateAndOnlyAFallbackSpeed) {
  const double range = 500.0 * kDeg;
  Rig rig(3, range);
  auto h = rig.policy();
  Rig::feed(*h, {0, 1, 2}, kT0, kT0 + 0.5);
  const double t = kT0 + 0.5 + kDt;
  ImuSample s = Rig::rest_sample(t);
  s.dtheta.x() = range * kDt;  // at full scale
  ImuSample b = s;
  EXPECT_TRUE(h->on_sample(0, s, b));
  EXPECT_EQ(h->monitor().stats(0).saturated_samples, 1u);
  EXPECT_TRUE(has_event(h->monitor(), "left", "gyro at full scale (500 deg/s)"));
  // The other wheel stands still: the substitute is the slowest rate the reading allows
  // (full scale), with the estimated bias added back.
  const WheelIns& w = rig.subs->wheel(0);
  const double floor = range * w.module().wheel_radius;
  EXPECT_DOUBLE_EQ(b.dtheta.x(), (w.omega_x_at_speed(floor) + w.ekf().errors().bg.x()) * kDt);
  // Its speed is not used while saturated (and saturation_hold after), but kept as a
  // lower bound; the others' are untouched.
  SpeedSelection sel;
  sel.speed_ok[0] = sel.speed_ok[1] = true;
  std::array<WheelVelocityInput, kMaxModules> wheel;
  for (int i = 0; i < 2; ++i) wheel[i] = rig.subs->wheel(i).own_velocity_input();
  h->screen_speeds(t, wheel, sel);
  EXPECT_FALSE(sel.speed_ok[0]);
  EXPECT_TRUE(sel.fallback[0]);
  EXPECT_TRUE(sel.speed_ok[1]);
  EXPECT_FALSE(sel.fallback[1]);
  // While saturated (and retry_after after), its INS is off for a known reason: its
  // inconsistent innovations blame nobody.
  const FaultOptions& o = rig.opt.faults;
  for (int k = 0; k < 2 * o.max_failed; ++k) h->on_velocity_update(0, report(2 * o.test_ratio), t);
  EXPECT_EQ(h->monitor().health(0), Health::kOk);
  // Back in range once the hold has passed.
  h->on_velocity_step(t + rig.opt.faults.saturation_hold + 0.01);
  EXPECT_TRUE(has_event(h->monitor(), "left", "gyro back in range"));
}

TEST(FaultHandler, WheelSpeedDisagreeingWithTheOtherAndItsInsIsLeftOut) {
  Rig rig;
  auto h = rig.policy();
  std::array<WheelVelocityInput, kMaxModules> wheel;
  for (int i = 0; i < 2; ++i) wheel[i] = rig.subs->wheel(i).own_velocity_input();
  wheel[0].measured_speed = 2.0;  // the left wheel spins at rest: slip
  SpeedSelection sel;
  sel.speed_ok[0] = sel.speed_ok[1] = true;
  const double t = kT0 + 20.0;
  h->screen_speeds(t, wheel, sel);
  EXPECT_FALSE(sel.speed_ok[0]);
  EXPECT_FALSE(sel.fallback[0]);
  EXPECT_TRUE(sel.speed_ok[1]);
  EXPECT_EQ(h->monitor().stats(0).speed_rejected, 1u);
  EXPECT_TRUE(has_event(h->monitor(), "left", "wheel speed 2.000 m/s disagrees"));
  // Agreeing again: used again, and said so.
  wheel[0].measured_speed = 0.0;
  sel = SpeedSelection();
  sel.speed_ok[0] = sel.speed_ok[1] = true;
  h->screen_speeds(t + 0.5, wheel, sel);
  EXPECT_TRUE(sel.speed_ok[0]);
  EXPECT_TRUE(has_event(h->monitor(), "left", "wheel speed agrees again"));
  // A wheel alone is not checked (against its own INS only, slip is not told from drift).
  sel = SpeedSelection();
  sel.speed_ok[0] = true;
  wheel[0].measured_speed = 2.0;
  h->screen_speeds(t + 1.0, wheel, sel);
  EXPECT_TRUE(sel.speed_ok[0]);
}

TEST(FaultHandler, HeadingOffTheOthersIsIsolatedAfterHeadingEpochs) {
  Rig rig;
  auto h = rig.policy();
  const FaultOptions& o = rig.opt.faults;
  Vec21 dx = Vec21::Zero();
  dx(PHI + 2) = 2.0 * o.heading_gate;  // turns the Body-INS's heading
  (*rig.subs)[2].ekf().feedback(dx);
  for (int k = 1; k < o.heading_epochs; ++k) h->on_position_step(kT0 + k);
  EXPECT_EQ(h->monitor().health(2), Health::kOk);
  h->on_position_step(kT0 + o.heading_epochs);
  EXPECT_EQ(h->monitor().health(2), Health::kIsolated);
  EXPECT_EQ(h->monitor().health(0), Health::kOk);
  EXPECT_TRUE(has_event(h->monitor(), "body", "heading 10.0 deg off the others' for 5 epochs"));
}

TEST(FaultHandler, RestartAfterIsolationTakesTheSensorErrorsOfBeforeTheFault) {
  Rig rig;
  auto h = rig.policy();
  const FaultOptions o;
  StrapdownEkf& ekf = (*rig.subs)[2].ekf();
  const ImuErrors good = ekf.errors();
  h->on_velocity_step(kT0);  // first snapshot: the good estimates
  ImuErrors bad = good;
  bad.bg.z() += 0.01;
  ekf.set_errors(bad);
  h->on_velocity_step(kT0 + FaultPolicy::kSnapshotInterval);  // 10-20 s old: still the good ones
  for (int k = 1; k <= o.max_failed; ++k) h->on_velocity_update(2, report(2 * o.test_ratio), kT0 + 11.0);
  ASSERT_EQ(h->monitor().health(2), Health::kIsolated);
  const double retry = kT0 + 11.0 + o.retry_after;
  Rig::feed(*h, {0, 1, 2}, kT0, retry - 0.1);
  h->on_velocity_step(retry);
  ASSERT_EQ(h->monitor().health(2), Health::kRealign);
  Rig::feed(*h, {0, 1, 2}, retry - 0.1, retry + o.realign_time + 0.01);
  EXPECT_EQ(h->monitor().health(2), Health::kProbation);
  // The policy decided the restart with the estimates of before the fault (the navigator's
  // parts set them: AidContext::act_on_faults); it changed no filter itself.
  const FaultActions act = h->take_actions();
  ASSERT_TRUE(act.restart.has_value());
  EXPECT_EQ(act.restart->module, 2);
  EXPECT_TRUE(act.restart->revert_errors);
  EXPECT_EQ(act.restart->errors.bg, good.bg);
  EXPECT_EQ(ekf.errors().bg, bad.bg);
  EXPECT_TRUE(act.forget_heading_offset[2]);  // its offset was tracked while the fault went undetected
}

TEST(OutputFusionOffsets, TheHeadingOffsetFollowsOverTheDeclaredWindow) {
  // fusion.heading_offset_window_s: each module's offset to the mean heading moves toward its
  // present value by the elapsed time over the window (e-folding); a tenth of the window moves
  // it ten times as far as a hundredth would.
  auto step = [](double window) {
    Rig rig(2);
    rig.opt.fusion.heading_offset_window = window;
    OutputFusion out(*rig.subs, *rig.filter, rig.frame, rig.opt, [](int, const TrajectoryRecord&) {});
    StaticAccumulator still;
    for (int k = 0; k < 100; ++k) still.add(Rig::rest_sample(kT0 - 0.5 + k * kDt));
    const OutputFusion::Use all{true, true};
    (*rig.subs)[1].start(still, 0.1, kT0);  // right: 0.1 rad off the left
    out.write(kT0, all, all);                // a first offset takes the present value
    double before = 0.0;
    EXPECT_TRUE(out.heading_offset(1, before));
    (*rig.subs)[1].start(still, 0.3, kT0);   // now 0.3 rad off
    out.write(kT0 + 1.0, all, all);
    double after = 0.0;
    EXPECT_TRUE(out.heading_offset(1, after));
    EXPECT_NEAR(before, 0.05, 1e-9);  // half the difference from the mean of two
    return after - before;
  };
  const double slow = step(100.0), fast = step(10.0);
  EXPECT_NEAR(slow, 0.01 * 0.1, 1e-9);
  EXPECT_NEAR(fast, 0.1 * 0.1, 1e-9);
}
