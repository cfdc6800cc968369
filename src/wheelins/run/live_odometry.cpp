// The odometry states of the live node (live_odometry.hpp).
#include "wheelins/run/live_odometry.hpp"

#include <cmath>

#include "wheelins/io/trajectory.hpp"

namespace wheelins {

namespace {
void put_block(std::array<double, 36>& cov, int at, const Mat3& block) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) cov[static_cast<std::size_t>((at + r) * 6 + at + c)] = block(r, c);
}
}  // namespace

OdometryState OdometryFrame::operator()(const TrajectoryRecord& r) {
  Vec3 xyz;
  Mat3 C;  // base_link (FLU) -> ENU
  tum_pose_from_ned(TumFrame::kEnu, r.p_inN, dcm_from_euler(r.rpy), xyz, C);
  if (!started_) {
    origin_enu_ = xyz;
    odom_from_enu_ = rot_z(std::atan2(C(1, 0), C(0, 0))).transpose();
  }
  OdometryState s;
  s.t = r.t;
  s.position = odom_from_enu_ * (xyz - origin_enu_);
  const Mat3 C_odom = odom_from_enu_ * C;
  s.orientation = Quat(C_odom).normalized();
  // The position sigmas are north, east, down: diagonal in ENU, turned into odom's axes.
  const Mat3 p_cov_enu = Vec3(r.p_std.y() * r.p_std.y(), r.p_std.x() * r.p_std.x(), r.p_std.z() * r.p_std.z()).asDiagonal();
  put_block(s.pose_covariance, 0, odom_from_enu_ * p_cov_enu * odom_from_enu_.transpose());
  put_block(s.pose_covariance, 3, Mat3(r.rpy_std.cwiseProduct(r.rpy_std).asDiagonal()));
  const Mat3 enu_from_ned = enu_ned_swap();
  s.linear = C.transpose() * enu_from_ned * r.v_inN;
  const Vec3 v_std_enu = enu_from_ned * r.v_std;  // east, north, up (a sign drops out squared)
  const Mat3 v_cov_enu = v_std_enu.cwiseProduct(v_std_enu).asDiagonal();
  put_block(s.twist_covariance, 0, C.transpose() * v_cov_enu * C);
  const double dt = r.t - last_t_;
  if (started_ && dt > 0.0) {
    s.angular = rotvec_from_quat(Quat(last_C_.transpose() * C)) / dt;  // the turn in base_link
    put_block(s.twist_covariance, 3, Mat3((2.0 / (dt * dt)) * r.rpy_std.cwiseProduct(r.rpy_std).asDiagonal()));
  } else {
    put_block(s.twist_covariance, 3, Mat3(1e6 * Mat3::Identity()));
  }
  last_C_ = C;
  last_t_ = r.t;
  started_ = true;
  return s;
}

}  // namespace wheelins
