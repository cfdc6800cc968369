// Rotation conversions of rotation.hpp: Euler angles, rotation vectors, quaternions.
#include "wheelins/math/rotation.hpp"

#include <cmath>

namespace wheelins {

double wrap_pi(double angle) {
  angle = std::remainder(angle, 2.0 * kPi);
  if (angle <= -kPi) angle += 2.0 * kPi;
  return angle;
}

Mat3 rot_x(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 m;
  m << 1, 0, 0, 0, c, -s, 0, s, c;
  return m;
}

Mat3 rot_y(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 m;
  m << c, 0, s, 0, 1, 0, -s, 0, c;
  return m;
}

Mat3 rot_z(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 m;
  m << c, -s, 0, s, c, 0, 0, 0, 1;
  return m;
}

Mat3 dcm_from_euler(const Vec3& rpy) { return rot_z(rpy.z()) * rot_y(rpy.y()) * rot_x(rpy.x()); }

Vec3 euler_from_dcm(const Mat3& C) {
  const double pitch = std::atan2(-C(2, 0), std::hypot(C(2, 1), C(2, 2)));
  const double roll = std::atan2(C(2, 1), C(2, 2));
  const double yaw = std::atan2(C(1, 0), C(0, 0));
  return {roll, pitch, yaw};
}

double yaw_from_dcm(const Mat3& C) { return std::atan2(C(1, 0), C(0, 0)); }

Quat quat_from_euler(const Vec3& rpy) { return Quat(dcm_from_euler(rpy)).normalized(); }

Quat quat_from_rotvec(const Vec3& rv) {
  const double angle = rv.norm();
  if (angle < 1e-8) {
    // Second-order series keeps unit norm to double precision.
    Quat q(1.0 - angle * angle / 8.0, 0.5 * rv.x(), 0.5 * rv.y(), 0.5 * rv.z());
    return q.normalized();
  }
  const double half = 0.5 * angle;
  const Vec3 v = rv * (std::sin(half) / angle);
  return Quat(std::cos(half), v.x(), v.y(), v.z());
}

Mat3 dcm_from_rotvec(const Vec3& rv) { return quat_from_rotvec(rv).toRotationMatrix(); }

Vec3 rotvec_from_quat(const Quat& q_in) {
  Quat q = q_in.normalized();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Vec3 v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v;
  const double angle = 2.0 * std::atan2(s, q.w());
  return v * (angle / s);
}

Mat3 so3_left_jacobian(const Vec3& phi) {
  const double a = phi.norm();
  const Mat3 K = skew(phi);
  if (a < 1e-5) return Mat3::Identity() + 0.5 * K + (1.0 / 6.0) * K * K;
  const double a2 = a * a;
  return Mat3::Identity() + ((1.0 - std::cos(a)) / a2) * K + ((a - std::sin(a)) / (a2 * a)) * K * K;
}

Mat3 so3_right_jacobian(const Vec3& phi) { return so3_left_jacobian(-phi); }

Mat3 so3_right_jacobian_inverse(const Vec3& phi) {
  const double a = phi.norm();
  const Mat3 K = skew(phi);
  if (a < 1e-5) return Mat3::Identity() + 0.5 * K + (1.0 / 12.0) * K * K;
  const double coef = 1.0 / (a * a) - (1.0 + std::cos(a)) / (2.0 * a * std::sin(a));
  return Mat3::Identity() + 0.5 * K + coef * K * K;
}

}  // namespace wheelins
