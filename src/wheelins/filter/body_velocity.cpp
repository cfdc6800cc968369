// The Body-INS velocity + NHC model of body_velocity.hpp: z_hat and H of eq. (6).
#include "wheelins/filter/body_velocity.hpp"

namespace wheelins {

BodyVelocityModel body_velocity_model(const BodyVelocityInput& in) {
  const Mat3& C = in.C_BtoW;
  const Mat3 Ct = C.transpose();
  const Vec3& l = in.lever_arm_inB;
  const Vec3 omega_nb = in.omega_ib_b - Ct * in.omega_ie_inW;

  BodyVelocityModel m;
  m.z_hat = in.C_BtoV * (Ct * in.v_IinW + omega_nb.cross(l));
  m.z_meas = Vec3(in.measured_speed, 0.0, 0.0);
  // Eq. (6) perturbed: C_hat_w^b = C^T (I + [phi x]), omega_hat = omega + b_g + diag(omega) s_g
  // (+ C^T [w_ie x] phi through the earth-rate term).
  m.H.block<3, 3>(0, V) = in.C_BtoV * Ct;
  m.H.block<3, 3>(0, PHI) =
      -in.C_BtoV * (Ct * skew(in.v_IinW) + skew(l) * Ct * skew(in.omega_ie_inW));
  m.H.block<3, 3>(0, BG) = -in.C_BtoV * skew(l);
  m.H.block<3, 3>(0, SG) = -in.C_BtoV * skew(l) * in.omega_ib_b.asDiagonal();
  return m;
}

}  // namespace wheelins
