// Strapdown mechanization (mechanization.hpp; docs/filter.md section 2): the
// rotation-exact and the classic two-sample attitude, velocity and position updates.
#include "wheelins/nav/mechanization.hpp"

namespace wheelins {

void mechanize(const MechanizationOptions& opt, const ImuSample& prev, const ImuSample& cur,
               NavState& state) {
  const double dt = cur.dt;
  const Vec3& dth = cur.dtheta;
  const Vec3& dv = cur.dvel;

  // Attitude increment of the b-frame with the two-sample coning correction.
  const Vec3 phi = dth + prev.dtheta.cross(dth) / 12.0;

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
  state.q_ItoW = (quat_from_rotvec(-zeta) * state.q_ItoW * quat_from_rotvec(phi)).normalized();
  state.t = cur.t;
}

}  // namespace wheelins
