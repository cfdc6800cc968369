// Installation calibration of a Wheel-IMU from its own data (docs/filter.md section 15):
// the axle direction in its frame (the mounting pitch and yaw) and its lever arm to the
// wheel centre, estimated by a recursive accumulator in front of the filter.
//
// Both quantities show in the data averaged over whole wheel turns, taken by angle (each
// sample weighted by the angle it turns through), where everything that turns with the
// wheel cancels: gravity, the vehicle's acceleration and its yaw rate seen from the wheel.
//  * Axle: the rotation vector of a turn is 2 pi times the spin axis (the mean spin axis of
//    Chen et al. 2019, the paper's ref. chen2019): summed over all turns, its direction in
//    the b-frame given by the manifest is the axle. Its component about the axle itself
//    (the mounting roll) is a wheel-angle offset: unobservable and without effect.
//  * Lever arm: the accelerometer at r = -l from the wheel centre reads, per turn, in the
//    axle-perpendicular plane (b y, z), the centripetal and tangential terms
//      f_y = c l_y + s l_z + b_y,   f_z = c l_z - s l_y + b_z,
//    c the turn's mean omega_x^2, s its mean angular acceleration, b the accelerometer bias.
//    The bias is taken as constant over a chunk of `chunk_s` and eliminated per chunk (the
//    regressors centred within the chunk), so a drifting bias does not leak into l; l is
//    observable where the wheel speed varies within chunks (stops, corners). l_x (along
//    the axle) gives no term: unobservable and without effect on the wheel velocity.
// Each estimate is combined with a Gaussian prior around the manifest value; with no
// information it stays there and says so (observed = false).
//
// Per sample: fixed-size arithmetic, no allocation.
#pragma once

#include <string>

#include "wheelins/nav/types.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

struct InstallationCalibrationOptions {
  double lever_arm_prior_std = 0.01;      ///< 1 sigma of the manifest lever arm [m]
  double mounting_prior_std = 1.0 * kDeg; ///< 1 sigma of the manifest axle direction [rad]
  double min_spin_rate = 1.0;             ///< a turn counts only while |omega_x| exceeds this [rad/s]
  double chunk_s = 60.0;                  ///< the accelerometer bias is constant within [s]
  int min_turns = 20;                     ///< fewer whole turns: nothing is estimated
  /// An estimate is "observed" when the data shrink the prior sigma below this fraction.
  double observed_ratio = 0.5;
};

/// An estimate with its 1-sigma and whether the data determined it.
struct CalibratedValue {
  double value = 0.0;
  double std = 0.0;
  bool observed = false;
};

struct WheelImuCalibration {
  std::string module;
  int turns = 0;                 ///< whole wheel turns used
  double spin_angle = 0.0;       ///< total angle turned through while rolling [rad]
  /// The axle-direction correction: the small rotation about b y and b z (b-frame of the
  /// manifest mounting) that carries the measured spin axis onto b x [rad].
  CalibratedValue axle_tilt_y, axle_tilt_z;
  /// The mounting angles with the correction applied (roll kept: unobservable) [rad].
  Vec3 mounting_rpy = Vec3::Zero();
  Vec3 manifest_mounting_rpy = Vec3::Zero();
  /// The lever arm in the corrected b-frame (x kept: unobservable) [m].
  CalibratedValue lever_arm[3];
  Vec3 manifest_lever_arm = Vec3::Zero();
  double accel_residual_rms = 0.0;  ///< per-turn residual of the lever-arm fit [m/s^2]

  Vec3 lever_arm_inB() const { return {lever_arm[0].value, lever_arm[1].value, lever_arm[2].value}; }
};

class WheelImuCalibrator {
 public:
  /// `static_start`, `static_end`: the static period, whose mean rate is the gyro bias.
  WheelImuCalibrator(const ImuModule& module, double static_start, double static_end,
                     const InstallationCalibrationOptions& opt = {});

  /// One raw sample in the sensor axes (as read from the module's file), in time order.
  void add(const ImuSample& sensor_sample);

  /// The estimates from the data so far (cheap; may be called at any time).
  WheelImuCalibration result() const;

  int turns() const { return turns_; }

 private:
  struct TurnSums {  // angle-weighted sums over the current turn
    double angle = 0.0, dt = 0.0, c = 0.0, s = 0.0;
    Vec3 f = Vec3::Zero(), rot = Vec3::Zero();
  };
  struct RegressionSums {  // sums over turns of the per-turn means
    double n = 0.0, c = 0.0, s = 0.0, cc = 0.0, ss = 0.0;
    Vec3 m = Vec3::Zero(), cm = Vec3::Zero(), sm = Vec3::Zero();
    Mat3 mm = Mat3::Zero();
  };
  void close_turn(int phase);
  void close_chunk();
  void reset_turns() {
    for (auto& t : turn_) t = TurnSums{};
    sequence_angle_ = 0.0;
  }
  /// Turns are taken at this many phases of the wheel, evenly spaced: the part of the
  /// vehicle's acceleration that changes within a turn leaves a residual that depends on
  /// where the turn starts, and it cancels over the phases.
  static constexpr int kPhases = 8;

  ImuModule module_;
  InstallationCalibrationOptions opt_;
  Mat3 C_StoB_;
  double static_start_, static_end_;
  Vec3 static_sum_ = Vec3::Zero();
  double static_dt_ = 0.0;
  double prev_wx_ = 0.0;
  bool have_prev_ = false;
  int spin_sign_ = 0;
  double chunk_start_ = 0.0;
  double t_ = 0.0;

  TurnSums turn_[kPhases];
  double sequence_angle_ = 0.0;  ///< angle turned since the wheel last started rolling
  RegressionSums chunk_;
  // Centred (within-chunk) sums over all closed chunks.
  double Scc_ = 0.0, Sss_ = 0.0, chunks_ = 0.0, rows_ = 0.0;
  Vec3 Scm_ = Vec3::Zero(), Ssm_ = Vec3::Zero();
  Mat3 Smm_ = Mat3::Zero();
  // Axle: the summed rotation vectors and the scatter of the per-turn directions.
  Vec3 axle_sum_ = Vec3::Zero(), dir_sum_ = Vec3::Zero();
  Mat3 dir_sq_ = Mat3::Zero();
  int turns_ = 0;
  double spin_angle_ = 0.0, rolling_time_ = 0.0;
};

}  // namespace wheelins
