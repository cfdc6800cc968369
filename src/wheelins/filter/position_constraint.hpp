// Multi-IMU position constraint (paper Section V-B, Algorithm 1, eq. 7-11 and H_mlt of
// Appendix B).
//
// Each subsystem i computes the reference point o (mid rear axle) from its own
// state, eq. (7) (oinwframe):  r_o = r_b - C_v^w r_b^v. For a Wheel-IMU the fixed point in the
// v-frame is the wheel centre, reached through the lever arm:
//   r_o = r_b + C_b^w l^b - C_v^w r_wc^v,  C_v^w = Rz(psi_v) Ry(theta) Rx(phi)
// with psi_v from the Wheel-IMU heading; for a Body-IMU C_v^w = C_b^w C_v^b.
// The weighted mean of all subsystems' o, eq. (8) (weightedpos), is the measurement for every
// subsystem (dz = r_o_hat - r_o_fused, eq. 11, mltIMUmeasurement), noise 0.2 m (Table 9).
#pragma once

#include "wheelins/filter/error_state.hpp"

namespace wheelins {

struct ReferencePointInput {
  bool wheel = true;                  ///< Wheel-IMU (true) or Body-IMU (false)
  Mat3 C_BtoW = Mat3::Identity();
  Vec3 p_IinW = Vec3::Zero();
  Vec3 lever_arm_inB = Vec3::Zero();  ///< Wheel-IMU: IMU centre -> wheel centre
  Vec3 p_inV = Vec3::Zero();          ///< wheel centre (wheel) or IMU centre (body) in v
  int axle_sign = 1;                  ///< Wheel-IMU
  double vehicle_roll = 0.0, vehicle_pitch = 0.0;  ///< Wheel-IMU: shared level
  /// Wheel-IMU on a steered wheel: its steering angle (its heading less the vehicle's) [rad].
  double steering = 0.0;
  Mat3 C_BtoV = Mat3::Identity();     ///< Body-IMU mounting
};

struct ReferencePointModel {
  Vec3 r_o = Vec3::Zero();  ///< o in the w-frame, eq. (7)
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();  ///< H_mlt
  /// Wheel-IMU: d r_o / d [vehicle roll, pitch] (the level shared by a Body-INS); zero for a
  /// Body-IMU, whose C_v^w is its own attitude.
  Eigen::Matrix<double, 3, 2> H_level = Eigen::Matrix<double, 3, 2>::Zero();
};

ReferencePointModel reference_point_model(const ReferencePointInput& in);

}  // namespace wheelins
