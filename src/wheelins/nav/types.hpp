// Small value types shared by every module.
#pragma once

#include <stdexcept>
#include <string>

#include "wheelins/math/rotation.hpp"

namespace wheelins {

/// One IMU epoch as increments over the interval (t - dt, t], in the IMU's b-frame.
/// Data recorded as rates are converted once at load: dtheta = gyro * dt, dvel = accel * dt
/// (a sample of an averaging IMU is the mean rate over its interval, so this is exact).
struct ImuSample {
  double t = 0.0;        ///< end of the interval [s]
  double dt = 0.0;       ///< interval length [s]
  Vec3 dtheta = Vec3::Zero();  ///< angle increment [rad]
  Vec3 dvel = Vec3::Zero();    ///< velocity increment (specific force integral) [m/s]
};

/// Position, velocity and attitude of an IMU in its w-frame (local level, NED).
struct NavState {
  double t = 0.0;
  Vec3 p_IinW = Vec3::Zero();  ///< IMU position [m]
  Vec3 v_IinW = Vec3::Zero();  ///< IMU velocity [m/s]
  Quat q_ItoW = Quat::Identity();  ///< attitude C_b^w as a unit quaternion
  Mat3 C_ItoW() const { return q_ItoW.toRotationMatrix(); }
};

/// The reason for every rejected input: names the file and the record or key.
/// Library code throws this (never exits); the CLI prints what() and exits non-zero.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace wheelins
