// Strapdown mechanization (mechanization.hpp; docs/filter.md section 2): the
// rotation-exact and the classic two-sample attitude, velocity and position updates.
#include "wheelins/nav/mechanization.hpp"

#include <cmath>

namespace wheelins {

AttitudeIncrement attitude_increment(const MechanizationOptions& opt, const ImuSample& prev,
                                     const ImuSample& cur) {
  const Vec3& dth = cur.dtheta;
  AttitudeIncrement a;
  // Beyond 2 rad of spin per sample (200 rad/s at 100 Hz: no wheel; a corrupt sample) the
  // split's 1 / sinc grows without bound: the two-sample form, which stays finite.
  if (!opt.spin_about_x || std::abs(dth.x()) > 2.0) {  // the two-sample coning correction
    a.phi = dth + prev.dtheta.cross(dth) / 12.0;
    a.q = quat_from_rotvec(a.phi);
    return a;
  }
  // R_x(theta/2) exp(q) R_x(theta/2) as a quaternion: with exp(q) = (w, 0, e_y, e_z) it is
  // (w cos(theta/2), w sin(theta/2), e_y, e_z) (the half-spins pass through the part
  // perpendicular to x), unit by construction.
  const double half = 0.5 * dth.x();
  const double ch = std::cos(half), sh = std::sin(half);
  const double sinc = std::abs(half) < 1e-4 ? 1.0 - half * half / 6.0 : sh / half;
  const double qy = dth.y() / sinc, qz = dth.z() / sinc;
  const double qn = std::sqrt(qy * qy + qz * qz);
  double w, f;  // cos(|q|/2), sin(|q|/2)/|q|
  if (qn < 1e-4) {
    w = 1.0 - qn * qn / 8.0;
    f = 0.5 - qn * qn / 48.0;
  } else {
    w = std::cos(0.5 * qn);
    f = std::sin(0.5 * qn) / qn;
  }
  a.q = Quat(w * ch, w * sh, f * qy, f * qz);
  const double vn = std::sqrt(w * w * sh * sh + f * f * qn * qn);
  const double angle = 2.0 * std::atan2(vn, w * ch);
  a.phi = vn < 1e-12 ? Vec3(2.0 * w * sh, 2.0 * f * qy, 2.0 * f * qz)
                     : Vec3(w * sh, f * qy, f * qz) * (angle / vn);
  return a;
}

void mechanize(const MechanizationOptions& opt, const ImuSample& prev, const ImuSample& cur,
               NavState& state) {
  const double dt = cur.dt;
  const Vec3& dth = cur.dtheta;
  const Vec3& dv = cur.dvel;

  // Attitude increment of the b-frame (the two-sample coning correction, or a wheel's spin
  // split off), and its rotation vector.
  const AttitudeIncrement inc = attitude_increment(opt, prev, cur);
  const Vec3& phi = inc.phi;

  // Velocity increment expressed in the b-frame at the start of the interval.
  Vec3 dv_b0;
  if (opt.method == MechanizationOptions::Method::kRotationExact) {
    dv_b0 = so3_right_jacobian_inverse(phi) * dv;
  } else {
    dv_b0 = dv + 0.5 * dth.cross(dv) + (prev.dtheta.cross(dv) + prev.dvel.cross(dth)) / 12.0;
  }

  // Rotation of the w-frame itself over the interval (earth rate; zero by default).
  const Vec3 zeta = opt.omega_ie_inW * dt;
  const Mat3 C_b0toW = state.C_ItoW();
  const Vec3 dv_f = C_b0toW * dv_b0 - 0.5 * zeta.cross(C_b0toW * dv_b0);

  // Gravity and Coriolis, evaluated at the extrapolated mid-interval velocity.
  const Vec3 g(0.0, 0.0, opt.gravity);
  const Vec3 v_mid = state.v_IinW + 0.5 * (dv_f + g * dt);
  const Vec3 dv_gc = (g - 2.0 * opt.omega_ie_inW.cross(v_mid)) * dt;

  const Vec3 v_new = state.v_IinW + dv_f + dv_gc;
  state.p_IinW += 0.5 * (state.v_IinW + v_new) * dt;
  state.v_IinW = v_new;

  // C_b(k)^w(k) = C_w(k-1)^w(k) C_b(k-1)^w(k-1) C_b(k)^b(k-1)
  state.q_ItoW = (quat_from_rotvec(-zeta) * state.q_ItoW * inc.q).normalized();
  state.t = cur.t;
}

}  // namespace wheelins
