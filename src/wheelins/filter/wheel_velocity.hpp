// Wheel velocity + non-holonomic constraint for a Wheel-IMU (paper Section V-A,
// eq. 4-5 and H_v of Appendix B).
//
// Predicted: the wheel-centre velocity in the v-frame,
//   z_hat = C_w^v(psi_v) [ v^w + C_b^w (omega_nb^b x l^b) ],
//   psi_v = yaw(C_b^w) - axle_sign * pi/2, vehicle roll/pitch given (0 on a plane,
//   or shared by a Body-INS).
// Measured: z = [ speed, 0, 0 ] (forward speed + NHC); the speed is this wheel's
// -axle_sign * r * mean(omega_x), or a mean over several Wheel-IMUs (Section III).
// Innovation dz = z_hat - z = H dx. H is exact to first order for the error
// conventions of error_state.hpp: it keeps the full heading sensitivity of the
// Wheel-IMU attitude (not only phi_z) and, because the speed comes from the
// compensated gyro, the b_g,x / s_g,x terms of the measured speed.
#pragma once

#include "wheelins/filter/error_state.hpp"

namespace wheelins {

struct WheelVelocityInput {
  Mat3 C_BtoW = Mat3::Identity();
  Vec3 v_IinW = Vec3::Zero();
  Vec3 omega_ib_b = Vec3::Zero();    ///< compensated angular rate at this epoch [rad/s]
  Vec3 omega_ie_inW = Vec3::Zero();  ///< earth rate in the w-frame (zero if ignored)
  Vec3 lever_arm_inB = Vec3::Zero(); ///< IMU centre -> wheel centre [m]
  double vehicle_roll = 0.0, vehicle_pitch = 0.0;  ///< [rad]
  /// A steered wheel's steering angle [rad] (filter/steering.hpp): the model holds in the
  /// wheel's own heading frame, whose level is the vehicle's turned by it (to first order in
  /// the tilt: roll' = c roll + s pitch, pitch' = -s roll + c pitch); H_level stays d/d the
  /// vehicle's [roll, pitch].
  double steering = 0.0;
  int axle_sign = 1;
  double measured_speed = 0.0;       ///< forward wheel speed [m/s]
  /// Sensitivity of measured_speed to this IMU's residual gyro-x bias and scale factor
  /// (-axle_sign * r and -axle_sign * r * mean omega_x for its own speed, scaled by its
  /// weight in a mean, zero when the speed comes from other IMUs only).
  double dspeed_dbgx = 0.0;
  double dspeed_dsgx = 0.0;
};

/// Fills the speed fields of `in` for a speed measured by this Wheel-IMU alone.
void set_own_wheel_speed(WheelVelocityInput& in, double radius, double mean_omega_x);

struct WheelVelocityModel {
  Vec3 z_hat = Vec3::Zero();   ///< predicted wheel-centre velocity in the v-frame
  Vec3 z_meas = Vec3::Zero();  ///< measured [speed, 0, 0]
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();
  /// d z_hat / d [vehicle roll, pitch]: the level is not this IMU's state but the one a
  /// Body-INS shares (Section V-A, theta_3, phi_3 in eq. 5); a centralized filter maps it
  /// onto the Body-INS attitude error with vehicle_level_sensitivity().
  Eigen::Matrix<double, 3, 2> H_level = Eigen::Matrix<double, 3, 2>::Zero();
  Vec3 innovation() const { return z_hat - z_meas; }
};

/// d [roll, pitch] / d phi of the vehicle attitude C_v^w = Rz(psi) Ry(theta) Rx(phi) under
/// the attitude error of the IMU that carries it (C_hat = exp(-[phi x]) C, phi in the
/// w-frame): minus the map from a w-frame rotation vector to Euler-angle increments.
Eigen::Matrix<double, 2, 3> vehicle_level_sensitivity(const Mat3& C_VtoW);

/// Vehicle heading implied by a Wheel-IMU attitude: yaw of the b x-axis - axle_sign * 90 deg.
double wheel_vehicle_heading(const Mat3& C_BtoW, int axle_sign);
/// d(psi_v)/d(phi): psi = atan2(c1_y, c1_x) of the b x-axis c1, and C_hat = (I - [phi x]) C
/// moves c1 by [c1 x] phi. Exact to first order for any Wheel-IMU attitude.
Eigen::RowVector3d wheel_heading_sensitivity(const Mat3& C_BtoW);

WheelVelocityModel wheel_velocity_model(const WheelVelocityInput& in);

/// Sets the measured [speed, 0, 0] of `m` and, since the speed comes from the compensated
/// gyro x (dz = z_hat - z_meas), its sensitivities to b_g,x and s_g,x in the first row of H.
void set_measured_speed(WheelVelocityModel& m, double speed, double dspeed_dbgx,
                        double dspeed_dsgx);

}  // namespace wheelins
