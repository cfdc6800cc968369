// Initial alignment from a static period (paper Section VI-A): roll and pitch
// from the mean specific force, gyro bias from the mean angular rate (less the
// earth rate), heading given (the paper takes it from the reference system).
#pragma once

#include "wheelins/filter/noise_identification.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

/// The samples of the static period: their means (the alignment) and the Allan variance of
/// each sensor (the noise at rest, noise_identification.hpp).
class StaticAccumulator {
 public:
  void add(const ImuSample& s) {
    sum_dtheta_ += s.dtheta;
    sum_dvel_ += s.dvel;
    sum_dt_ += s.dt;
    ++count_;
    if (s.dt > 0.0) {
      gyro_.add(s.dtheta / s.dt, s.dt);
      accel_.add(s.dvel / s.dt, s.dt);
    }
  }
  int count() const { return count_; }
  double duration() const { return sum_dt_; }
  Vec3 mean_omega() const { return sum_dtheta_ / sum_dt_; }
  Vec3 mean_f() const { return sum_dvel_ / sum_dt_; }
  const AllanAccumulator& gyro_allan() const { return gyro_; }
  const AllanAccumulator& accel_allan() const { return accel_; }

 private:
  Vec3 sum_dtheta_ = Vec3::Zero(), sum_dvel_ = Vec3::Zero();
  double sum_dt_ = 0.0;
  int count_ = 0;
  AllanAccumulator gyro_, accel_;
};

/// Roll and pitch of the b-frame from a static mean specific force (f^b = -C_n^b g^n).
Vec3 level_from_specific_force(const Vec3& mean_f);

/// C_b^n with the levelled roll/pitch and the yaw that gives the vehicle the requested
/// heading through C_v^n = C_b^n C_v^b (C_BtoV: the IMU's attitude in the vehicle).
Mat3 align_attitude(const Vec3& mean_f, double vehicle_heading, const Mat3& C_BtoV);

}  // namespace wheelins
