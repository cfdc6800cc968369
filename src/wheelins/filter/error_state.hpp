// The 21-state error model of paper Section IV-B, eq. (1):
//   x = [dr^n, dv^n, phi, b_g, b_a, s_g, s_a]
// Error conventions (documented in docs/filter.md, used by every Jacobian):
//   r_hat = r + dr, v_hat = v + dv, C_hat = (I - [phi x]) C      (C = C_b^w)
//   b_g, b_a, s_g, s_a are the residual errors of the estimated totals:
//   omega_hat - omega = b_g + diag(omega) s_g (+ noise), likewise for f.
#pragma once

#include <Eigen/Core>

#include "wheelins/nav/types.hpp"

namespace wheelins {

/// Named offsets of the error-state blocks (KF-GINS style).
enum StateIndex : int { P = 0, V = 3, PHI = 6, BG = 9, BA = 12, SG = 15, SA = 18 };
constexpr int kStateDim = 21;

/// The name of error state k ("dr_x" .. "sa_z"), as reports write it; "?" out of range.
inline const char* error_state_name(int k) {
  static const char* names[kStateDim] = {"dr_x", "dr_y", "dr_z", "dv_x", "dv_y", "dv_z",
                                         "phi_x", "phi_y", "phi_z", "bg_x", "bg_y", "bg_z",
                                         "ba_x", "ba_y", "ba_z", "sg_x", "sg_y", "sg_z",
                                         "sa_x", "sa_y", "sa_z"};
  return k >= 0 && k < kStateDim ? names[k] : "?";
}

using Vec21 = Eigen::Matrix<double, kStateDim, 1>;
using Mat21 = Eigen::Matrix<double, kStateDim, kStateDim>;

/// Estimated IMU errors (totals, fed back after each update).
struct ImuErrors {
  Vec3 bg = Vec3::Zero();  ///< gyro bias [rad/s]
  Vec3 ba = Vec3::Zero();  ///< accelerometer bias [m/s^2]
  Vec3 sg = Vec3::Zero();  ///< gyro scale-factor error [-]
  Vec3 sa = Vec3::Zero();  ///< accelerometer scale-factor error [-]
};

/// Removes the estimated errors from a raw increment sample:
/// omega = (omega_raw - b_g) / (1 + s_g), f = (f_raw - b_a) / (1 + s_a), component-wise.
inline ImuSample compensate(const ImuSample& raw, const ImuErrors& e) {
  ImuSample s = raw;
  s.dtheta = (raw.dtheta - e.bg * raw.dt).cwiseQuotient((Vec3::Ones() + e.sg));
  s.dvel = (raw.dvel - e.ba * raw.dt).cwiseQuotient((Vec3::Ones() + e.sa));
  return s;
}

}  // namespace wheelins
