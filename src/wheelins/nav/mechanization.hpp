// Strapdown mechanization in the local-level w-frame (flat earth, constant
// gravity along +z; the earth rotation rate as an option).
//
// Paper Section IV-B: "the conventional strapdown inertial navigation is
// leveraged to predict the IMU state". Two velocity-increment algorithms:
//
//  kRotationExact (default): attitude by the two-sample coning correction,
//    phi_k = dtheta_k + dtheta_{k-1} x dtheta_k / 12, and the velocity increment
//    in the b-frame at the start of the interval
//        dv^{b(k-1)} = J_r(phi_k)^{-1} dv_k,
//    which is exact when the angular rate is constant over the interval and the
//    specific force is constant in the navigation frame. A Wheel-IMU turning at
//    15 rad/s sees gravity rotate by 0.075 rad per 200 Hz sample; this form
//    stays exact there (docs/filter.md, section 2).
//
//  kClassicTwoSample: the textbook rotation + sculling correction
//        dv^{b(k-1)} = dv_k + dtheta_k x dv_k / 2 + (dtheta_{k-1} x dv_k + dv_{k-1} x dtheta_k) / 12,
//    which assumes rates linear in time and has a systematic error
//    |phi|^2 |dv| / 6 along gravity on a spinning wheel. Kept for comparison.
#pragma once

#include "wheelins/nav/types.hpp"

namespace wheelins {

struct MechanizationOptions {
  enum class Method { kRotationExact, kClassicTwoSample };
  Method method = Method::kRotationExact;
  double gravity = 9.80665;          ///< magnitude of gravity along +z of the w-frame [m/s^2]
  Vec3 omega_ie_inW = Vec3::Zero();  ///< earth rotation rate in the w-frame (zero: ignored)
};

/// Propagates `state` over the interval of `cur` (bias-compensated increments).
/// `prev` is the previous compensated sample (for the coning term); pass `cur`
/// again on the first epoch.
void mechanize(const MechanizationOptions& opt, const ImuSample& prev, const ImuSample& cur,
               NavState& state);

}  // namespace wheelins
