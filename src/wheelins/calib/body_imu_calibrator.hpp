// A Body-IMU's mounting against the vehicle frame (docs/filter.md section 15): the roll and
// pitch from the axis the vehicle turns about (BodyImuCalibrator), the yaw and the position
// from its lateral specific force against the Wheel-IMUs' axle accelerometers
// (estimate_body_yaw()).
#pragma once

#include <vector>

#include "wheelins/calib/bins.hpp"
#include "wheelins/calib/calibration_types.hpp"
#include "wheelins/calib/wheel_imu_calibrator.hpp"
#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

/// The Body-IMU's mounting roll and pitch from its own data (docs/filter.md section 15):
/// the vehicle's z-axis is the axis it turns about. On any ground a vehicle yaws about its
/// own z, so the principal axis of the rates' scatter while turning is v z in the b-frame
/// (the terrain's pitch and roll rates are smaller and uncorrelated with the yaw rate).
/// It also keeps the data in time bins for the yaw (estimate_body_yaw()).
class BodyImuCalibrator {
 public:
  /// `expected_end`: as WheelImuCalibrator's (the bin series is reserved up to it).
  BodyImuCalibrator(const ImuModule& module, double static_start, double static_end,
                    const InstallationCalibrationOptions& opt = {}, double expected_end = 0.0);
  void add(const ImuSample& sensor_sample);
  /// Roll and pitch; the yaw is the manifest's until estimate_body_yaw() sets it.
  BodyImuCalibration result() const;
  const ImuModule& module() const { return module_; }
  const BinSeries<BodyBin>& bins() const { return bins_; }

 private:
  void close_chunk();
  ImuModule module_;
  InstallationCalibrationOptions opt_;
  Mat3 C_BtoV_;
  StaticPeriodSums static_;
  double chunk_start_ = -1.0, t_ = 0.0;
  // Turning: the rate scatter, whole run and current chunk; the per-chunk axes.
  Mat3 turn_all_ = Mat3::Zero(), turn_chunk_ = Mat3::Zero();
  double turn_time_ = 0.0, turn_chunk_time_ = 0.0, yaw_sum_ = 0.0;
  Vec3 axis_sum_ = Vec3::Zero(), axis_sq_ = Vec3::Zero();
  int axis_chunks_ = 0;
  BinSeries<BodyBin> bins_;
};

/// The Body-IMU's mounting yaw (docs/filter.md section 15), from the specific force (gravity
/// included) that it shares with the wheels' axles, not from the NHC (see there): a
/// Wheel-IMU's accelerometer along its axle (v y) reads the vehicle's lateral specific force
/// (the lateral acceleration and the ground's bank), which is the Body-IMU's too but for the
/// rotational terms of their offset. A yaw error delta adds delta times the forward specific
/// force (the acceleration and the ground's grade) to the Body-IMU's lateral one:
///   f_y(body) - f_axle(wheels) = delta f_x(body) + psi'' dp_x - psi'^2 dp_y + b,
/// dp the Body-IMU's position relative to the wheels' mean, b the accelerometer biases,
/// eliminated per chunk of `chunk_s`. Fitted over time bins of `yaw_bin_s` for delta and
/// the correction of dp from the manifest's. No wheel speed enters (slip does not bias it).
/// `wheel_results`: the Wheel-IMUs' estimates (their axles), in the order of `wheels`.
/// Sets the yaw, the position corrections and `mounting_rpy` of `body_result`; without a
/// Wheel-IMU, or with too little acceleration, the manifest's yaw is kept (not observed).
void estimate_body_yaw(const BodyImuCalibrator& body, const std::vector<const WheelImuCalibrator*>& wheels,
                       const std::vector<WheelImuCalibration>& wheel_results,
                       const InstallationCalibrationOptions& opt, BodyImuCalibration& body_result);

}  // namespace wheelins
