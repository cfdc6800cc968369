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
//
//  The attitude of a Wheel-IMU (spin_about_x): the two-sample coning term assumes a rate
//  linear in time, and a wheel spinning at Omega about b x while the vehicle turns at
//  psi_dot is a rate turning at Omega in the b-frame. Its error is a yaw-rate scale error
//  of order (Omega dt)^4: -44 ppm at 45 rad/s and 200 Hz, -708 ppm at 100 Hz (a car at
//  15 m/s; 0.35 deg of heading RMSE over the default scenario on error-free data). For a
//  constant spin theta = dtheta_x and a constant turn rate in the w-frame the rotation over
//  the interval is exactly
//      R_x(theta / 2) exp(q) R_x(theta / 2),  q = (0, dtheta_y, dtheta_z) / sinc(theta / 2),
//  the turn applied in the b-frame of mid-interval, where the measured increment of a rate
//  turning by theta over the interval is shortened by sinc(theta / 2) (docs/filter.md 2).
//  The velocity increment uses the rotation vector of that rotation.
#pragma once

#include "wheelins/nav/types.hpp"

namespace wheelins {

struct MechanizationOptions {
  enum class Method { kRotationExact, kClassicTwoSample };
  Method method = Method::kRotationExact;
  double gravity = 9.80665;          ///< magnitude of gravity along +z of the w-frame [m/s^2]
  Vec3 omega_ie_inW = Vec3::Zero();  ///< earth rotation rate in the w-frame (zero: ignored)
  /// The b x-axis is a wheel's axle: the attitude splits its spin off (above). Set by the
  /// Wheel-INS for itself.
  bool spin_about_x = false;
};

/// The rotation of the b-frame over one interval of increments `cur` (`prev` the one
/// before, for the coning term): C_b(k)^b(k-1) and its rotation vector.
struct AttitudeIncrement {
  Quat q;
  Vec3 phi;
};
AttitudeIncrement attitude_increment(const MechanizationOptions& opt, const ImuSample& prev,
                                     const ImuSample& cur);

/// Propagates `state` over the interval of `cur` (bias-compensated increments).
/// `prev` is the previous compensated sample (for the coning term); pass `cur`
/// again on the first epoch.
void mechanize(const MechanizationOptions& opt, const ImuSample& prev, const ImuSample& cur,
               NavState& state);

}  // namespace wheelins
