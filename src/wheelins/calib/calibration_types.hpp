// The installation calibration's options and results (docs/filter.md section 15): what the
// calibrators of calib/ take (InstallationCalibrationOptions) and what they estimate, a
// Wheel-IMU's axle, lever arm and relative radius (WheelImuCalibration) and a Body-IMU's
// mounting (BodyImuCalibration), each value with its 1 sigma (CalibratedValue).
#pragma once

#include <string>

#include "wheelins/math/rotation.hpp"

namespace wheelins {

struct InstallationCalibrationOptions {
  double lever_arm_prior_std = 0.01;      ///< 1 sigma of the manifest lever arm [m]
  double mounting_prior_std = 1.0 * kDeg; ///< 1 sigma of the manifest axle direction [rad]
  double min_spin_rate = 1.0;             ///< a turn counts only while |omega_x| exceeds this [rad/s]
  double chunk_s = 60.0;                  ///< the accelerometer bias is constant within [s]
  int min_turns = 20;                     ///< fewer whole turns: nothing is estimated
  /// An estimate is "observed" when the data shrink the prior sigma below this fraction.
  double observed_ratio = 0.5;
  double rate_bin_s = 1.0;                ///< time bins of the relative-radius fit [s]
  double radius_prior_std = 0.01;         ///< 1 sigma of the manifest radii's ratio [-]
  double body_mounting_prior_std = 1.0 * kDeg;  ///< 1 sigma of a Body-IMU's manifest mounting
  double position_prior_std = 0.02;       ///< 1 sigma of a Body-IMU's manifest position relative to the wheels [m]
  double min_yaw_rate = 0.1;              ///< a Body-IMU counts as turning above this [rad/s]
  double yaw_bin_s = 0.1;                 ///< time bins of a Body-IMU's yaw fit [s]
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
  /// The wheel radius relative to the Wheel-IMU(s) on the other side of the vehicle: the
  /// radius with the relative correction applied (the two sides' mean kept at the
  /// manifest's; the absolute radius is not observable), its 1 sigma [m]. Without a
  /// Wheel-IMU on the other side: the manifest's radius, not observed.
  CalibratedValue wheel_radius;
  double manifest_wheel_radius = 0.0;

  Vec3 lever_arm_inB() const { return {lever_arm[0].value, lever_arm[1].value, lever_arm[2].value}; }
};

/// A Body-IMU's mounting against the vehicle frame (C_b^v as ZYX Euler angles).
struct BodyImuCalibration {
  std::string module;
  double turning_time = 0.0;  ///< time spent turning faster than min_yaw_rate [s]
  /// The correction of the vehicle's z-axis (the yaw axis) as seen in the v-frame given by
  /// the manifest: small rotations about v x and v y [rad].
  CalibratedValue tilt_x, tilt_y;
  /// The correction of the mounting yaw: a rotation about v z, after the tilt [rad]; from
  /// the lateral specific force against the Wheel-IMUs' axle accelerometers
  /// (estimate_body_yaw(); without a Wheel-IMU in the run: the manifest's, not observed).
  CalibratedValue yaw;
  /// Fitted with the yaw: the correction of the Body-IMU's position in the v-frame (x, y)
  /// relative to the mean of the Wheel-IMUs' manifest positions [m], so that the offset
  /// between them is the true one.
  CalibratedValue position_x, position_y;
  Vec3 manifest_position = Vec3::Zero();  ///< the manifest's position_v_m [m]
  int yaw_bins = 0;                 ///< time bins used by the yaw fit
  double yaw_excitation = 0.0;      ///< RMS forward specific force about its chunk means [m/s^2]
  double yaw_residual_rms = 0.0;    ///< RMS residual of the yaw fit per bin [m/s^2]
  Vec3 mounting_rpy = Vec3::Zero();  ///< with the corrections applied [rad]
  Vec3 manifest_mounting_rpy = Vec3::Zero();
};

}  // namespace wheelins
