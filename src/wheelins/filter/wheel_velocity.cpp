// The Wheel-IMU velocity + NHC model of wheel_velocity.hpp: z_hat and H_v of eq. (5)
// (Appendix B), the vehicle heading of a Wheel-IMU and its sensitivities.
#include "wheelins/filter/wheel_velocity.hpp"

#include <cmath>

namespace wheelins {

double wheel_vehicle_heading(const Mat3& C, int axle_sign) {
  return wrap_pi(yaw_from_dcm(C) - axle_sign * 0.5 * kPi);
}

void set_own_wheel_speed(WheelVelocityInput& in, double radius, double mean_omega_x) {
  in.measured_speed = -in.axle_sign * radius * mean_omega_x;
  in.dspeed_dbgx = -in.axle_sign * radius;
  in.dspeed_dsgx = -in.axle_sign * radius * mean_omega_x;
}

Eigen::RowVector3d wheel_heading_sensitivity(const Mat3& C) {
  const Vec3 c1 = C.col(0);
  const double h2 = c1.x() * c1.x() + c1.y() * c1.y();
  return Eigen::RowVector3d(-c1.y() / h2, c1.x() / h2, 0.0) * skew(c1);
}

Eigen::Matrix<double, 2, 3> vehicle_level_sensitivity(const Mat3& C) {
  // C = Rz(psi) Ry(theta) Rx(phi): omega^w = psi' e_z + theta' Rz e_y + phi' Rz Ry e_x, so
  // phi' = (cos psi w_x + sin psi w_y) / cos theta, theta' = -sin psi w_x + cos psi w_y.
  // exp(-[phi x]) C is a w-frame rotation by -phi.
  const Vec3 e = euler_from_dcm(C);
  const double cp = std::cos(e.z()), sp = std::sin(e.z()), ct = std::cos(e.y());
  Eigen::Matrix<double, 2, 3> M;
  M << cp / ct, sp / ct, 0.0, -sp, cp, 0.0;
  return -M;
}

WheelVelocityModel wheel_velocity_model(const WheelVelocityInput& in) {
  const Mat3& C = in.C_BtoW;
  const Vec3& l = in.lever_arm_inB;
  const double psi = wheel_vehicle_heading(C, in.axle_sign);
  // The level in the wheel's heading frame (a steered wheel's is turned by the steering).
  const double cs = std::cos(in.steering), sn = std::sin(in.steering);
  const double roll = cs * in.vehicle_roll + sn * in.vehicle_pitch;
  const double pitch = -sn * in.vehicle_roll + cs * in.vehicle_pitch;

  // C_v^w = Rz(psi) Ry(theta) Rx(phi); its transpose maps w-frame vectors into the v-frame.
  const Mat3 Rz = rot_z(psi), Ryx = rot_y(pitch) * rot_x(roll);
  const Mat3 C_WtoV = (Rz * Ryx).transpose();

  const Vec3 omega_nb = in.omega_ib_b - C.transpose() * in.omega_ie_inW;
  const Vec3 rot_vel_inW = C * omega_nb.cross(l);  // C_b^w (omega_nb x l)
  const Vec3 u = in.v_IinW + rot_vel_inW;          // wheel-centre velocity, w-frame

  WheelVelocityModel m;
  m.z_hat = C_WtoV * u;

  // d z_hat / d dv  (eq. 5, second term)
  m.H.block<3, 3>(0, V) = C_WtoV;

  // d z_hat / d phi: through C_b^w in the lever-arm term and the earth-rate term,
  // and through the heading psi_v = yaw(C_b^w) - axle_sign*pi/2 (the A and B blocks of App. B).
  const Eigen::RowVector3d dpsi_dphi = wheel_heading_sensitivity(C);
  const Vec3 dz_dpsi = -(Ryx.transpose() * skew(Vec3::UnitZ()) * Rz.transpose()) * u;
  m.H.block<3, 3>(0, PHI) = C_WtoV * (skew(rot_vel_inW) - C * skew(l) * C.transpose() *
                                                               skew(in.omega_ie_inW)) +
                            dz_dpsi * dpsi_dphi;

  // d z_hat / d b_g and d s_g (the D block): omega_hat = omega + b_g + diag(omega) s_g.
  const Mat3 Hbg = -C_WtoV * C * skew(l);
  m.H.block<3, 3>(0, BG) = Hbg;
  m.H.block<3, 3>(0, SG) = Hbg * in.omega_ib_b.asDiagonal();
  set_measured_speed(m, in.measured_speed, in.dspeed_dbgx, in.dspeed_dsgx);
  // z_hat = Rx(phi)^T Ry(theta)^T Rz^T u; d Rx^T/d phi = -[e_x x] Rx^T, same for Ry.
  const Mat3 Rx = rot_x(roll), Ry = rot_y(pitch);
  m.H_level.col(0) = -skew(Vec3::UnitX()) * C_WtoV * u;
  m.H_level.col(1) = -Rx.transpose() * skew(Vec3::UnitY()) * Ry.transpose() * Rz.transpose() * u;
  if (in.steering != 0.0) {
    // d [roll', pitch'] / d [roll, pitch] = [c s; -s c].
    Eigen::Matrix2d T;
    T << cs, sn, -sn, cs;
    m.H_level = (m.H_level * T).eval();
  }

  return m;
}

void set_measured_speed(WheelVelocityModel& m, double speed, double dspeed_dbgx,
                        double dspeed_dsgx) {
  m.z_meas = Vec3(speed, 0.0, 0.0);
  m.H(0, BG) -= dspeed_dbgx;
  m.H(0, SG) -= dspeed_dsgx;
}

}  // namespace wheelins
