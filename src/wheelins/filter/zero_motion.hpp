// The measurements of a vehicle standing still (docs/filter.md section 17): every IMU on it,
// a Wheel-IMU's included (its wheel does not turn), is at rest on the earth, so
//   zero velocity (ZUPT):    z_hat = v^w of the IMU,                 measured 0;
//   zero angular rate (ZARU): z_hat = omega_ib^b - C_w^b omega_ie^w,  measured 0,
// the rate the compensated gyro shows beyond the earth's rotation (the mean over the
// standstill window). With the error conventions of error_state.hpp
// (v_hat = v + dv, C_hat = (I - [phi x]) C, omega_hat = omega + b_g + diag(omega) s_g):
//   H_zupt = [0, I, 0, ...]
//   H_zaru: phi block C^T [omega_ie x], b_g block I, s_g block diag(omega).
#pragma once

#include "wheelins/filter/error_state.hpp"

namespace wheelins {

struct ZeroMotionInput {
  Mat3 C_BtoW = Mat3::Identity();
  Vec3 v_IinW = Vec3::Zero();
  Vec3 omega_ib_b = Vec3::Zero();    ///< compensated angular rate, mean over the window [rad/s]
  Vec3 omega_ie_inW = Vec3::Zero();  ///< earth rate in the w-frame (zero if ignored)
};

struct ZeroMotionModel {
  Vec3 z_hat = Vec3::Zero();
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();
  /// z_hat - z_meas, the measurement being zero.
  Vec3 innovation() const { return z_hat; }
};

ZeroMotionModel zero_velocity_model(const ZeroMotionInput& in);
ZeroMotionModel zero_rate_model(const ZeroMotionInput& in);

}  // namespace wheelins
