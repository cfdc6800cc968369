// The steering observer (filter/steering.hpp) on exact Ackermann kinematics: a wheel centre
// x ahead of the rear axle, steered by delta(t), rolling at speed v(t); the vehicle turns at
// v sin(delta) / x and the wheel at that plus delta'.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "wheelins/filter/steering.hpp"
#include "wheelins/math/rotation.hpp"

using namespace wheelins;

namespace {

constexpr double kX = 2.6;    // wheel centre ahead of the rear axle [m]
constexpr double kDt = 0.005;  // 200 Hz
constexpr double kRadius = 0.35;  // wheel radius [m]

struct Drive {
  std::function<double(double)> delta;  // true steering [rad]
  std::function<double(double)> speed;  // wheel centre speed [m/s]
};

struct Result {
  double max_error_after = 0.0;  // |delta_hat - delta| after `settle_t` [rad]
  double turn = 0.0;             // the onset's turns of the wheel's navigation, summed
  double vehicle_heading_error = 0.0;  // at the end: (wheel heading - delta_hat) - vehicle's
  double max_heading_error_rolled = 0.0;  // the same, its largest from 0.3 m rolled on
  bool settled = false;
};

/// Drives for `duration`: the wheel's heading is integrated from its yaw rate, starting at
/// the vehicle's heading (0) plus the observer's delta (0: the start's unknown), turned by the
/// observer's onset correction; `reference` passes the true vehicle heading over the onset.
/// `misalignment`: the IMU's axes off the wheel's by this angle [rad], so that the spin leaks
/// into the yaw rate as misalignment * omega * cos(theta) and into the heading as
/// misalignment * sin(theta) (theta: the wheel's rotation angle).
Result drive(const Drive& d, double duration, double settle_t, bool reference, double misalignment = 0.0) {
  SteeringObserver obs(kX, kRadius, SteeringOptions{});
  obs.arm(0.0);
  Result r;
  double psi_v = 0.0;            // true vehicle heading
  double psi_w = obs.angle();    // the wheel's navigated heading (vehicle's + delta_hat)
  double theta = 0.0;            // the wheel's rotation angle
  double rolled = 0.0;
  for (double t = 0.0; t < duration; t += kDt) {
    const double v = d.speed(t);
    const double ddelta = (d.delta(t + 1e-6) - d.delta(t - 1e-6)) / 2e-6;
    const double wv = v * std::sin(d.delta(t)) / kX;  // vehicle yaw rate
    const double ww = wv + ddelta;                    // wheel yaw rate
    psi_v += wv * kDt;
    psi_w += ww * kDt;
    const double leak_rate = misalignment * v / kRadius * std::cos(theta);
    theta += v / kRadius * kDt;
    const auto st = obs.step(ww + leak_rate, v, kDt, psi_w + misalignment * std::sin(theta),
                             reference ? psi_v : SteeringObserver::kNoHeading);
    if (st.turn != 0.0) {
      r.turn += st.turn;
      psi_w += st.turn;
    }
    rolled += v * kDt;
    if (rolled >= 0.3)
      r.max_heading_error_rolled =
          std::max(r.max_heading_error_rolled, std::abs(wrap_pi(psi_w - obs.angle() - psi_v)));
    if (t > settle_t)
      r.max_error_after = std::max(r.max_error_after, std::abs(obs.angle() - d.delta(t + kDt)));
  }
  r.vehicle_heading_error = wrap_pi(psi_w - obs.angle() - psi_v);
  r.settled = obs.settled();
  return r;
}

double ramp(double t, double t0, double t1) { return std::clamp((t - t0) / (t1 - t0), 0.0, 1.0); }

}  // namespace

TEST(Steering, TracksTheSteeringOfAWindingDrive) {
  // Straight wheels at the start, then +-25 deg weaving at 8 m/s.
  Drive d{[](double t) { return 25.0 * kDeg * std::sin(0.4 * t) * ramp(t, 3.0, 5.0); },
          [](double t) { return 8.0 * ramp(t, 0.0, 3.0); }};
  const Result r = drive(d, 60.0, 5.0, false);
  EXPECT_TRUE(r.settled);
  EXPECT_LT(r.max_error_after, 0.3 * kDeg);
  EXPECT_LT(std::abs(r.vehicle_heading_error), 0.3 * kDeg);
}

TEST(Steering, StartWithTheWheelsTurnedTwentyDegrees) {
  // Alone: the steering held while the car starts to roll is measured from the wheel's turn.
  Drive d{[](double t) { return 20.0 * kDeg * (1.0 - ramp(t, 6.0, 8.0)); },
          [](double t) { return 3.0 * ramp(t, 1.0, 4.0); }};
  const Result r = drive(d, 30.0, 4.0, false);
  EXPECT_TRUE(r.settled);
  EXPECT_NEAR(r.turn, 20.0 * kDeg, 0.5 * kDeg);
  // From 0.3 m rolled on the turn so far sets delta_0, long before the onset's 2.2 m.
  EXPECT_LT(r.max_heading_error_rolled, 1.0 * kDeg);
  EXPECT_LT(r.max_error_after, 0.5 * kDeg);
  EXPECT_LT(std::abs(r.vehicle_heading_error), 0.5 * kDeg);
}

TEST(Steering, TheStartsTurnIsMeasuredOverWholeRevolutions) {
  // The IMU 0.1 deg off the wheel's axes: over the 0.5 m asked (0.23 of a revolution) the
  // spin's leak would be up to 0.1 deg of false turn, 0.5 deg of delta_0; the onset rolls
  // one whole revolution instead, over which it cancels. The same with another IMU's heading.
  Drive d{[](double) { return 20.0 * kDeg; }, [](double t) { return 3.0 * ramp(t, 1.0, 4.0); }};
  const Result alone = drive(d, 20.0, 6.0, false, 0.1 * kDeg);
  const Result referenced = drive(d, 20.0, 6.0, true, 0.1 * kDeg);
  for (const Result* r : {&alone, &referenced}) {
    EXPECT_TRUE(r->settled);
    EXPECT_NEAR(r->turn, 20.0 * kDeg, 0.1 * kDeg);
    EXPECT_LT(std::abs(r->vehicle_heading_error), 0.15 * kDeg);
  }
}

TEST(Steering, ACarThatCreepsBeforeItRollsTurnsWithTheWheel) {
  // Wheels turned 20 deg, the car creeps at 4 cm/s for 3 s (12 cm: the vehicle turns 0.9
  // deg), then drives off. Creeping is rolling: the vehicle turns with the wheel, alone or
  // with another IMU's heading (taken as steering at rest, the 0.9 deg would stay in the
  // vehicle's heading).
  Drive d{[](double) { return 20.0 * kDeg; },
          [](double t) { return t < 1.0 ? 0.0 : t < 4.0 ? 0.04 : 0.04 + 3.0 * ramp(t, 4.0, 7.0); }};
  const Result alone = drive(d, 20.0, 9.0, false);
  const Result referenced = drive(d, 20.0, 9.0, true);
  for (const Result* r : {&alone, &referenced}) {
    EXPECT_TRUE(r->settled);
    EXPECT_LT(std::abs(r->vehicle_heading_error), 0.1 * kDeg);
  }
}

TEST(Steering, SteeringWhileStartingToRollNeedsAnotherImusHeading) {
  // The driver turns from 20 deg to 5 deg as the car starts to roll: alone, the onset takes
  // the wheel's turn for the vehicle's and keeps the difference in the heading; with the
  // vehicle's heading from another IMU the error is found.
  Drive d{[](double t) { return (20.0 - 15.0 * ramp(t, 1.0, 2.5)) * kDeg; },
          [](double t) { return 2.0 * ramp(t, 1.0, 3.0); }};
  const Result alone = drive(d, 30.0, 10.0, false);
  const Result referenced = drive(d, 30.0, 10.0, true);
  EXPECT_GT(std::abs(alone.vehicle_heading_error), 3.0 * kDeg);
  EXPECT_LT(std::abs(referenced.vehicle_heading_error), 0.5 * kDeg);
  EXPECT_LT(referenced.max_error_after, 0.5 * kDeg);
}

TEST(Steering, SteeringAtRestTurnsTheWheelOnly) {
  // At rest the wheel's yaw rate is the steering rate: the vehicle's implied yaw rate is 0.
  SteeringObserver obs(kX, kRadius, SteeringOptions{});
  obs.arm(0.0);
  for (int k = 0; k < 200; ++k) {
    obs.step(0.2, 0.0, kDt);
    EXPECT_DOUBLE_EQ(obs.vehicle_yaw_rate(0.2), 0.0);
  }
  EXPECT_NEAR(obs.angle(), 0.2, 1e-12);
  EXPECT_FALSE(obs.settled());
}

TEST(Steering, AStandingWheelsNoisySpeedIsNotRolling) {
  // The speed a standing wheel's gyro gives: white noise of 4 mm/s per sample (a real car's
  // front wheel at idle, 120 Hz). Steered at rest for 10 s, the wheel does not start to
  // roll: all its turn is steering.
  SteeringObserver obs(kX, kRadius, SteeringOptions{});
  obs.arm(0.0);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.004);
  const double dt = 1.0 / 120.0;
  for (int k = 0; k < 1200; ++k) {
    const auto st = obs.step(0.02, noise(rng), dt);
    ASSERT_FALSE(st.rolling_began) << "epoch " << k;
  }
  EXPECT_NEAR(obs.angle(), 0.2, 1e-9);
}
