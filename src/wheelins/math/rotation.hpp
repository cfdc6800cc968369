// Rotations and frames.
//
// Conventions (paper Table 2):
//   v-frame: origin at the mid rear axle, x forward, y right, z down.
//   n/w-frame: north-east-down; each IMU has its own w-frame (aligned with its
//              initial n-frame).
//   b-frame (Wheel-IMU): x along the axle pointing right; y, z in the wheel plane.
//   b-frame (Body-IMU):  x forward, y right, z down.
// Names say which frame a quantity is in: C_BtoW maps b-frame vectors into the
// w-frame (the paper's C_b^w), p_IinW is the IMU position in the w-frame.
// Euler angles are ZYX (yaw, then pitch, then roll): C_b^n = Rz(yaw) Ry(pitch) Rx(roll),
// stored as a vector [roll, pitch, yaw] in radians.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace wheelins {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

/// Cross-product (skew-symmetric) matrix: skew(a) * b == a.cross(b).
inline Mat3 skew(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

/// Wraps an angle to (-pi, pi].
double wrap_pi(double angle);

/// C_b^n from ZYX Euler angles [roll, pitch, yaw].
Mat3 dcm_from_euler(const Vec3& rpy);
/// ZYX Euler angles [roll, pitch, yaw] from C_b^n; pitch in [-pi/2, pi/2].
Vec3 euler_from_dcm(const Mat3& C);
/// Yaw of the frame's x-axis, atan2(C(1,0), C(0,0)); well defined as long as the
/// x-axis is not vertical, whatever the roll (a Wheel-IMU rolls continuously).
double yaw_from_dcm(const Mat3& C);

Quat quat_from_euler(const Vec3& rpy);

/// exp map: rotation vector (axis * angle) to rotation matrix / quaternion.
Mat3 dcm_from_rotvec(const Vec3& rv);
Quat quat_from_rotvec(const Vec3& rv);
/// log map: quaternion to rotation vector, angle in [0, pi].
Vec3 rotvec_from_quat(const Quat& q);

/// Elementary rotations of a frame about its own axis (C_b^a for b rotated by angle about a's axis).
/// North-east-down <-> east-north-up (REP 103's world frame): x and y swapped, z turned; its
/// own inverse.
inline Mat3 enu_ned_swap() { return (Mat3() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished(); }
/// Body forward-right-down <-> forward-left-up (REP 103's base_link): y and z turned; its own
/// inverse.
inline Mat3 frd_flu_swap() { return Vec3(1.0, -1.0, -1.0).asDiagonal(); }

Mat3 rot_x(double angle);
Mat3 rot_y(double angle);
Mat3 rot_z(double angle);

/// SO(3) Jacobians: J_l(phi) = sum_k [phi]^k/(k+1)!, J_r(phi) = J_l(-phi).
/// integral_0^1 exp(s*[phi]) ds == J_l(phi).
Mat3 so3_left_jacobian(const Vec3& phi);
Mat3 so3_right_jacobian(const Vec3& phi);
Mat3 so3_right_jacobian_inverse(const Vec3& phi);

}  // namespace wheelins
