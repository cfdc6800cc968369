// The steering angle of a Wheel-IMU on a steered wheel (docs/filter.md section 16).
//
// A steered wheel turns against the vehicle about its (vertical) kingpin by the steering
// angle delta: its heading is the vehicle's plus delta (positive: turned right; w-frame z
// down). Its own constraints (eq. 5: the wheel centre moves along the wheel plane) hold in
// its wheel frame as they are; what ties it to the vehicle (the heading it shares, eq. 7's
// reference point, the vehicle's yaw rate) needs delta.
//
// Rolling without side slip (Ackermann), the wheel centre, x ahead of the rear axle
// (the unsteered wheels' axle, through o), moves at right angles to the line from the
// instantaneous centre of rotation, which lies on the rear axle's line. Whatever its
// lateral offset, the vehicle then turns at
//     psi_v' = v sin(delta) / x                       (v: the wheel centre's speed)
// and the wheel, which turns with the vehicle and with the steering, at
//     psi_w' = psi_v' + delta'.
// The observer integrates
//     delta' = psi_w' - (v / x) sin(delta)
// from the wheel's own yaw rate and speed: an error in delta decays at the rate v cos(delta) / x
// (within a few metres of travel), and the gyro's yaw rate needs no other IMU. At rest the
// equation is delta' = psi_w': steering a standing car turns the wheel only.
//
// What the wheel alone cannot tell is delta at the start (the wheel's heading then is the
// vehicle's plus an unknown delta_0; the later data forget it, as the error decays, but the
// vehicle's heading keeps it). The start ("onset") settles it over the first metres rolled,
// after which the wheel's navigation state is turned by the error found about the vertical
// through where it started to roll (its heading and its path since then were off by it):
//  - with another IMU that knows the vehicle's heading (an unsteered wheel, a body): over
//    `reference_onset_distance`, the vehicle's turn per metre from it gives the mean of
//    sin(delta) (Ackermann, as above), and the wheel's heading less the vehicle's gives delta
//    less the wheel's heading error at every epoch: their means give the error, whatever the
//    driver does with the steering meanwhile;
//  - alone, over `onset_distance`, delta is held (the vehicle is taken to turn with the
//    wheel: the steering held while the car starts to roll), then delta_0 =
//    asin(x * turn / distance) from the wheel's turn over that distance. A driver who steers
//    while starting to roll leaves an error of the steering's change in the heading (in a
//    local frame, a turn of the whole path after the first metres). Until the end of the
//    onset, the turn so far sets delta_0 from `provisional_distance` on, so that the wheel's
//    path (and the vehicle's point) is not carried off by the armed delta meanwhile.
// Both onsets last a whole number of wheel revolutions (at least the distance asked): the
// IMU's axes are never exactly the wheel's (mounting residuals, the gyro's non-orthogonal
// axes), so the spin leaks into the yaw rate and the heading the wheel reports as a
// sinusoid of the wheel's rotation angle, of amplitude the misalignment. Over a part of a
// revolution it does not cancel: 0.05 deg of misalignment is up to 0.1 deg of false turn,
// which over half a metre is 0.5 deg of delta_0 on a car (x = 2.6 m); over whole
// revolutions it cancels.
#pragma once

namespace wheelins {

struct SteeringOptions {
  /// Rolled before delta_0 is taken from the turn [m], rounded up to whole revolutions.
  double onset_distance = 0.5;
  double reference_onset_distance = 2.0;  ///< ... from another IMU's heading [m], the same
  /// Alone, from this distance rolled on, the turn so far sets delta_0 at every epoch until
  /// the onset's end measures it [m].
  double provisional_distance = 0.1;
  /// Below it the wheel stands [m/s], its speed low-passed over `standstill_time` [s]: a
  /// car that creeps (an automatic at idle, a slow start) turns with the wheel, and a wheel
  /// that creeps at a few cm/s with its steering held is not steered (0.04 m crept at 20 deg
  /// would be 0.3 deg of the vehicle's heading, and the onset never gets it back). Its
  /// speed from the gyro at rest: white noise of a few mm/s per sample, a tenth of that
  /// low-passed.
  double standstill_speed = 0.005;
  double standstill_time = 0.1;
};

class SteeringObserver {
 public:
  /// What one step asks of the wheel's navigation.
  struct Step {
    bool rolling_began = false;  ///< the wheel started to roll (after arm()): the pivot
    double turn = 0.0;           ///< turn the wheel's navigation state by this about the
                                 ///< vertical through the pivot [rad] (once, at the onset)
  };

  SteeringObserver() = default;
  /// `distance_ahead`: the wheel centre's distance ahead of the rear axle [m] (> 0);
  /// `wheel_radius` [m] (> 0) sets the onsets' whole revolutions.
  SteeringObserver(double distance_ahead, double wheel_radius, const SteeringOptions& opt);

  /// A new start (or restart): delta from `delta` until the onset measures it.
  void arm(double delta) {
    delta_ = delta;
    rate_ = 0.0;
    phase_ = Phase::kStanding;
    turn_ = distance_ = 0.0;
    referenced_ = false;
    gap_sum_ = 0.0;
  }

  /// One IMU epoch: the wheel's yaw rate (w-frame z, its spin left out) [rad/s], the wheel
  /// centre's speed along the wheel [m/s], the epoch's length [s]; over the onset, the
  /// wheel's heading (of its wheel plane) and the vehicle's from another IMU (NaN: none).
  Step step(double wheel_yaw_rate, double speed, double dt, double wheel_heading = 0.0,
            double vehicle_heading = kNoHeading);
  static constexpr double kNoHeading = 1e300;

  double angle() const { return delta_; }  ///< delta [rad]
  double rate() const { return rate_; }    ///< d delta / dt at the last step [rad/s]
  /// The vehicle's yaw rate the wheel implies (its own less the steering rate) [rad/s].
  double vehicle_yaw_rate(double wheel_yaw_rate) const { return wheel_yaw_rate - rate_; }
  /// delta_0 is measured (the onset is over).
  bool settled() const { return phase_ == Phase::kTracking; }

 private:
  enum class Phase { kStanding, kOnset, kTracking };
  double x_ = 1.0;
  SteeringOptions opt_;
  double onset_ = 0.5, reference_onset_ = 2.0;  // the onsets' distances: whole revolutions
  double delta_ = 0.0, rate_ = 0.0;
  double speed_lp_ = 0.0;  // the speed low-passed over opt_.standstill_time
  Phase phase_ = Phase::kStanding;
  double turn_ = 0.0, distance_ = 0.0;  // over the onset: the wheel's turn, its signed travel
  // With a reference: the vehicle's heading at the onset's start and at the last epoch, and
  // the integral of (wheel heading - vehicle heading) over the distance rolled.
  bool referenced_ = false;
  double ref_start_ = 0.0, ref_last_ = 0.0, gap_sum_ = 0.0, gap_last_ = 0.0;
};

}  // namespace wheelins
