// Body-INS velocity + NHC (paper Section V-A, eq. 6): the velocity of a point on
// the rear axle (a wheel centre, or o when the speed is a mean of both wheels)
// predicted from the Body-IMU state and the fixed mounting C_b^v,
//   z_hat = C_b^v [ C_w^b v^w + omega_nb^b x l^b ],
// measured as [wheel speed, 0, 0] (the speed comes from the Wheel-IMUs).
#pragma once

#include "wheelins/filter/error_state.hpp"

namespace wheelins {

struct BodyVelocityInput {
  Mat3 C_BtoW = Mat3::Identity();
  Vec3 v_IinW = Vec3::Zero();
  Vec3 omega_ib_b = Vec3::Zero();     ///< compensated angular rate [rad/s]
  Vec3 omega_ie_inW = Vec3::Zero();
  Mat3 C_BtoV = Mat3::Identity();     ///< mounting C_b^v (calibrated)
  Vec3 lever_arm_inB = Vec3::Zero();  ///< Body-IMU centre -> measured point, b-frame [m]
  double measured_speed = 0.0;        ///< forward speed of that point [m/s]
};

struct BodyVelocityModel {
  Vec3 z_hat = Vec3::Zero();
  Vec3 z_meas = Vec3::Zero();
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();
  Vec3 innovation() const { return z_hat - z_meas; }
};

BodyVelocityModel body_velocity_model(const BodyVelocityInput& in);

}  // namespace wheelins
