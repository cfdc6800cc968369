// The standstill measurements of zero_motion.hpp.
#include "wheelins/filter/zero_motion.hpp"

#include "wheelins/math/rotation.hpp"

namespace wheelins {

ZeroMotionModel zero_velocity_model(const ZeroMotionInput& in) {
  ZeroMotionModel m;
  m.z_hat = in.v_IinW;
  m.H.block<3, 3>(0, V).setIdentity();
  return m;
}

ZeroMotionModel zero_rate_model(const ZeroMotionInput& in) {
  // C_hat^T w_ie = C^T (I + [phi x]) w_ie = C^T w_ie - C^T [w_ie x] phi.
  ZeroMotionModel m;
  const Mat3 Ct = in.C_BtoW.transpose();
  m.z_hat = in.omega_ib_b - Ct * in.omega_ie_inW;
  m.H.block<3, 3>(0, PHI) = Ct * skew(in.omega_ie_inW);
  m.H.block<3, 3>(0, BG).setIdentity();
  m.H.block<3, 3>(0, SG) = in.omega_ib_b.asDiagonal();
  return m;
}

}  // namespace wheelins
