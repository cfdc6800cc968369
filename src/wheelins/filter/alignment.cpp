// Static alignment (alignment.hpp): roll and pitch from the mean specific force, and the
// attitude that gives the vehicle a stated heading.
#include "wheelins/filter/alignment.hpp"

#include <cmath>

namespace wheelins {

Vec3 level_from_specific_force(const Vec3& f) {
  return {std::atan2(-f.y(), -f.z()), std::atan2(f.x(), std::hypot(f.y(), f.z())), 0.0};
}

Mat3 align_attitude(const Vec3& mean_f, double vehicle_heading, const Mat3& C_BtoV) {
  Vec3 rpy = level_from_specific_force(mean_f);
  // A yaw change of the IMU rotates the vehicle about the vertical by the same angle.
  const double heading_at_zero = yaw_from_dcm(dcm_from_euler(rpy) * C_BtoV.transpose());
  rpy.z() = wrap_pi(vehicle_heading - heading_at_zero);
  return dcm_from_euler(rpy);
}

}  // namespace wheelins
