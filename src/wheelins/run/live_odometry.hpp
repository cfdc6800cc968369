// The vehicle's state as a ROS odometry message carries it (REP 103 / REP 105; docs/live.md):
// the pose of base_link (x forward, y left, z up) in the odom frame, whose origin is the first
// published pose and whose axes are east-north-up turned about up so that x is the first
// heading (at the first state x, y and the heading are 0; roll and pitch are the vehicle's,
// odom's z is up). No ROS type here: the node (app/ros/) copies these into its messages.
#pragma once

#include <array>

#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/trajectory_record.hpp"

namespace wheelins {

struct OdometryState {
  double t = 0.0;
  Vec3 position = Vec3::Zero();          ///< base_link's origin in odom [m]
  Quat orientation = Quat::Identity();   ///< base_link -> odom
  /// Row-major 6x6 over x, y, z and the rotations about x, y, z [m^2, rad^2], as
  /// nav_msgs/Odometry's pose.covariance: the run's position sigmas (north, east, down) turned
  /// into odom's axes, its roll, pitch and heading sigmas on the diagonal.
  std::array<double, 36> pose_covariance{};
  Vec3 linear = Vec3::Zero();    ///< velocity in base_link [m/s]
  /// Angular rate in base_link [rad/s]: the turn between this state and the one before over
  /// the time between them (0 at the first state).
  Vec3 angular = Vec3::Zero();
  /// Row-major 6x6 as twist.covariance: the velocity sigmas turned into base_link; the
  /// angular rate's variance from the attitude sigmas of the two states (2 sigma^2 / dt^2, the
  /// bound without their correlation; 1e6 at the first state: not known).
  std::array<double, 36> twist_covariance{};
};

/// Turns the run's records into odometry states; the first record fixes the odom frame.
class OdometryFrame {
 public:
  OdometryState operator()(const TrajectoryRecord& r);

 private:
  bool started_ = false;
  Vec3 origin_enu_ = Vec3::Zero();
  Mat3 odom_from_enu_ = Mat3::Identity();
  Mat3 last_C_ = Mat3::Identity();
  double last_t_ = 0.0;
};

}  // namespace wheelins
