// One epoch of a navigation solution: what the fusion produces and what the
// trajectory files (io/trajectory.hpp) and the evaluation read and write.
#pragma once

#include "wheelins/nav/earth.hpp"

namespace wheelins {

/// One epoch of a navigation solution for the vehicle reference point o
/// (mid rear axle), with 1-sigma figures and the IMU errors of the subsystem
/// that produced it.
struct TrajectoryRecord {
  double t = 0.0;
  Vec3 p_inN = Vec3::Zero();     ///< north, east, down from the origin [m]
  earth::Geodetic lla;           ///< latitude/longitude [rad], height [m]
  Vec3 v_inN = Vec3::Zero();     ///< velocity [m/s]
  Vec3 rpy = Vec3::Zero();       ///< vehicle roll, pitch, heading [rad]
  Vec3 p_std = Vec3::Zero(), v_std = Vec3::Zero(), rpy_std = Vec3::Zero();
  Vec3 bg = Vec3::Zero(), ba = Vec3::Zero();  ///< gyro [rad/s] / accel [m/s^2] bias
  Vec3 sg = Vec3::Zero(), sa = Vec3::Zero();  ///< scale-factor errors [-]
  Vec3 bg_std = Vec3::Zero(), ba_std = Vec3::Zero(), sg_std = Vec3::Zero(), sa_std = Vec3::Zero();
};

}  // namespace wheelins
