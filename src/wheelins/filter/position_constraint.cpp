// The reference point model of position_constraint.hpp: r_o of eq. (7) for a Wheel-IMU
// (through the wheel centre) or a Body-IMU, and its H_mlt (eq. 11, Appendix B).
#include "wheelins/filter/position_constraint.hpp"

#include "wheelins/filter/wheel_velocity.hpp"

namespace wheelins {

ReferencePointModel reference_point_model(const ReferencePointInput& in) {
  const Mat3& C = in.C_BtoW;
  ReferencePointModel m;
  m.H.block<3, 3>(0, P) = Mat3::Identity();
  if (in.wheel) {
    const double psi = wheel_vehicle_heading(C, in.axle_sign) - in.steering;
    const Mat3 Rz = rot_z(psi), Ryx = rot_y(in.vehicle_pitch) * rot_x(in.vehicle_roll);
    const Vec3 a = Ryx * in.p_inV;            // so that C_v^w r^v = Rz(psi) a
    const Vec3 Cl = C * in.lever_arm_inB;
    m.r_o = in.p_IinW + Cl - Rz * a;
    // (I - [phi x]) C l = C l + [(C l) x] phi; the heading enters through psi(C_b^w).
    const Eigen::RowVector3d dpsi_dphi = wheel_heading_sensitivity(C);
    const Vec3 dRa_dpsi = Rz * skew(Vec3::UnitZ()) * a;
    m.H.block<3, 3>(0, PHI) = skew(Cl) - dRa_dpsi * dpsi_dphi;
    // Eq. (7) with C_v^w = Rz Ry(theta) Rx(phi): d(Ry Rx)/d phi = Ry Rx [e_x x], d/d theta = Ry [e_y x] Rx.
    const Mat3 Rx = rot_x(in.vehicle_roll), Ry = rot_y(in.vehicle_pitch);
    m.H_level.col(0) = -Rz * Ry * Rx * skew(Vec3::UnitX()) * in.p_inV;
    m.H_level.col(1) = -Rz * Ry * skew(Vec3::UnitY()) * Rx * in.p_inV;
  } else {
    // r_o = r_b - C_b^w C_v^b r_b^v; (I - [phi x]) C_v^w r = C_v^w r + [(C_v^w r) x] phi.
    const Vec3 Cr = C * in.C_BtoV.transpose() * in.p_inV;
    m.r_o = in.p_IinW - Cr;
    m.H.block<3, 3>(0, PHI) = -skew(Cr);
  }
  return m;
}

}  // namespace wheelins
