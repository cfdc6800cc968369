// The live node's odometry states (run/live_odometry.hpp): REP 103/105 frames, the odom frame
// at the first pose, the covariances turned with the axes.
#include <gtest/gtest.h>

#include <cmath>

#include "wheelins/run/live_odometry.hpp"

namespace wheelins {
namespace {

TrajectoryRecord record(double t, const Vec3& p_ned, const Vec3& rpy, const Vec3& v_ned) {
  TrajectoryRecord r;
  r.t = t;
  r.p_inN = p_ned;
  r.rpy = rpy;
  r.v_inN = v_ned;
  r.p_std = Vec3(1.0, 2.0, 3.0);   // north, east, down
  r.v_std = Vec3(0.1, 0.2, 0.3);
  r.rpy_std = Vec3(0.01, 0.02, 0.03);
  return r;
}

TEST(LiveOdometry, TheFirstPoseIsTheOriginAndTheVehicleDrivesAlongX) {
  OdometryFrame frame;
  // Heading north-east (45 deg), driving forward at 10 m/s.
  const double psi = 45.0 * kDeg;
  const Vec3 fwd(std::cos(psi), std::sin(psi), 0.0);
  const OdometryState s0 = frame(record(10.0, Vec3(5, 7, -1), Vec3(0, 0, psi), 10.0 * fwd));
  EXPECT_NEAR(s0.position.norm(), 0.0, 1e-12);
  EXPECT_NEAR((s0.orientation.toRotationMatrix() - Mat3::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s0.linear - Vec3(10, 0, 0)).norm(), 0.0, 1e-12);  // base_link: x forward
  const OdometryState s1 = frame(record(11.0, Vec3(5, 7, -1) + 10.0 * fwd + Vec3(0, 0, -2), Vec3(0, 0, psi), 10.0 * fwd));
  EXPECT_NEAR((s1.position - Vec3(10, 0, 2)).norm(), 0.0, 1e-12);  // 2 m up: odom z is up
}

TEST(LiveOdometry, ATurnToTheLeftIsAPositiveYawRateAndAnglesFollowFlu) {
  OdometryFrame frame;
  frame(record(0.0, Vec3::Zero(), Vec3(0, 0, 0.0), Vec3::Zero()));
  // NED heading decreasing = turning left = counter-clockwise seen from above: +z in FLU.
  const OdometryState s = frame(record(0.5, Vec3::Zero(), Vec3(0.0, 0.0, -0.2), Vec3::Zero()));
  EXPECT_NEAR((s.angular - Vec3(0, 0, 0.4)).norm(), 0.0, 1e-12);
  Mat3 C = s.orientation.toRotationMatrix();
  EXPECT_NEAR(std::atan2(C(1, 0), C(0, 0)), 0.2, 1e-12);  // yaw left of the start
  // NED roll +0.1 (right side down) is FLU roll +0.1 about x forward (y and z both turn);
  // NED pitch +0.05 (nose up) is FLU pitch -0.05 about y left.
  C = frame(record(1.0, Vec3::Zero(), Vec3(0.1, 0.05, 0.0), Vec3::Zero())).orientation.toRotationMatrix();
  EXPECT_NEAR(std::atan2(C(2, 1), C(2, 2)), 0.1, 1e-12);
  EXPECT_NEAR(std::asin(-C(2, 0)), -0.05, 1e-12);
}

TEST(LiveOdometry, CovariancesAreTheRunsSigmasTurnedIntoTheFrames) {
  OdometryFrame frame;
  const double psi = 30.0 * kDeg;
  const OdometryState s = frame(record(0.0, Vec3::Zero(), Vec3(0, 0, psi), Vec3::Zero()));
  const auto& P = s.pose_covariance;
  // Horizontal: north 1, east 2 (ENU x = east): turned by -30 deg about up; its trace stays.
  EXPECT_NEAR(P[0] + P[7], 1.0 + 4.0, 1e-12);
  const double c = std::cos(psi), sn = std::sin(psi);
  // odom x = ENU along the heading: forward unit vector in ENU is (sin psi, cos psi).
  EXPECT_NEAR(P[0], sn * sn * 4.0 + c * c * 1.0, 1e-12);
  EXPECT_NEAR(P[14], 9.0, 1e-12);
  EXPECT_NEAR(P[21], 1e-4, 1e-15);
  EXPECT_NEAR(P[28], 4e-4, 1e-15);
  EXPECT_NEAR(P[35], 9e-4, 1e-15);
  EXPECT_EQ(P[1], P[6]);  // symmetric
  const auto& T = s.twist_covariance;
  EXPECT_NEAR(T[0] + T[7] + T[14], 0.01 + 0.04 + 0.09, 1e-12);
  EXPECT_EQ(T[35], 1e6);  // the first state: no rate known
}

}  // namespace
}  // namespace wheelins
