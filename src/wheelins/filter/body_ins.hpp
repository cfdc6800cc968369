// Body-INS: the subsystem of a Body-IMU (paper Section III: "the odometry-aided
// INS implemented using the Body-IMU and the wheel speed indicated by the
// Wheel-IMU"): strapdown EKF + velocity/NHC updates of eq. (6) at a rear-axle
// point, with the wheel speed given by the Wheel-INSs. It shares the vehicle
// roll and pitch with the Wheel-INSs.
#pragma once

#include "wheelins/filter/body_velocity.hpp"
#include "wheelins/filter/subsystem.hpp"

namespace wheelins {

struct BodyInsOptions {
  Vec3 velocity_std = Vec3(0.05, 0.04, 0.04);  ///< forward, lateral, vertical [m/s] (Table 9)
  double gate = 0.0;
  InitialUncertainty init;
  /// The scale factor of the gyro axis along the vehicle's yaw axis (a yaw-rate scale
  /// factor, unobservable without a heading reference; docs/filter.md 13.4).
  YawScaleFactors yaw_scale_factors = YawScaleFactors::kHeld;
};

class BodyIns final : public Subsystem {
 public:
  BodyIns(const ImuModule& module, const BodyInsOptions& opt, const MechanizationOptions& mech);

  /// The Body-IMU b-frame is its sensor frame; C_b^v enters the models instead.
  ImuSample to_body(const ImuSample& sensor) const override { return sensor; }
  void start(const StaticAccumulator& stat, double vehicle_heading, double t0) override;
  void restart(const Vec3& mean_f_inB, const VehicleFix& fix) override;
  /// Forward speed of o from the filter's own velocity [m/s].
  double ins_speed() const { return (C_VtoW().transpose() * reference_velocity_inW()).x(); }

  /// C_v^w = C_b^w C_v^b.
  Mat3 C_VtoW() const { return ekf_.state().C_ItoW() * C_BtoV_.transpose(); }
  double vehicle_heading() const override { return yaw_from_dcm(C_VtoW()); }
  /// Vehicle [roll, pitch, heading].
  Vec3 vehicle_rpy() const { return euler_from_dcm(C_VtoW()); }
  Eigen::RowVector3d heading_sensitivity() const override;
  ReferencePointInput reference_point_input() const override;
  Vec3 reference_velocity_inW() const override;

  /// Velocity + NHC model (eq. 6) at the rear-axle point p_inV (a wheel centre, or o)
  /// moving at `speed`.
  BodyVelocityModel velocity_model(double speed, const Vec3& point_inV) const;
  Mat3 velocity_noise() const { return opt_.velocity_std.cwiseAbs2().asDiagonal(); }
  double velocity_gate() const { return opt_.gate; }

 private:
  BodyInsOptions opt_;
  Mat3 C_BtoV_;
};

}  // namespace wheelins
