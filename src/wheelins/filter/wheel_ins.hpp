// Wheel-INS: the navigation subsystem of one Wheel-IMU (paper Sections IV-V-A;
// Niu et al. 2021). Strapdown EKF + wheel velocity/NHC updates at a fixed rate,
// the wheel speed from the Wheel-IMU's own gyro, and the vehicle state (heading,
// reference point) derived from the Wheel-IMU state.
#pragma once

#include <array>

#include "wheelins/filter/steering.hpp"
#include "wheelins/filter/subsystem.hpp"
#include "wheelins/filter/turn_average.hpp"
#include "wheelins/filter/wheel_velocity.hpp"

namespace wheelins {

struct WheelInsOptions {
  double velocity_update_interval = 0.5;       ///< [s]; the paper's 2 Hz (scheduled by the navigator)
  double speed_window = 0.05;                  ///< gyro-x averaging window for the speed [s]
  Vec3 velocity_std = Vec3(0.03, 0.02, 0.02);  ///< forward, lateral, vertical [m/s] (Table 9)
  double gate = 0.0;                           ///< innovation gate on the test ratio; 0 = off
  InitialUncertainty init;
  /// The scale factors of the gyro axes in the wheel plane (b y, z): together they are the
  /// yaw-rate scale factor, unobservable without a heading reference (docs/filter.md 13.4).
  YawScaleFactors yaw_scale_factors = YawScaleFactors::kHeld;
  /// Estimate the scale factor of the accelerometer along the axle (b x). It sees only the
  /// lateral specific force (the centripetal acceleration of turns, gravity through roll),
  /// which on a course that turns mostly one way is indistinguishable from its bias: held
  /// by default (docs/filter.md 13.4).
  bool estimate_axle_accel_scale_factor = false;
  /// The velocity update over a whole wheel turn (filter/turn_average.hpp): the model of
  /// eq. (5) and the measured speed averaged over the last whole turn, so the errors that turn
  /// with the wheel (lever arm, axle direction) cancel. Off (the default; measured in
  /// docs/filter.md 15.1): the model at the update epoch and the speed over speed_window
  /// (the paper's).
  bool turn_average = false;
  /// The longest span kept for it [s]; slower than a turn in this, the update is the
  /// instantaneous one.
  double turn_window = 4.0;
  /// A steered wheel's steering observer (ImuModule::steered; filter/steering.hpp).
  SteeringOptions steering;
};

class WheelIns final : public Subsystem {
 public:
  static constexpr int kMaxWindow = 256;
  static constexpr int kMaxTurnEpochs = 1 << 15;

  WheelIns(const ImuModule& module, const WheelInsOptions& opt, const MechanizationOptions& mech);

  /// Rotates a raw sample from the sensor axes into the ideal wheel b-frame (mounting angles).
  ImuSample to_body(const ImuSample& sensor) const override;

  /// Aligns from the static mean (b-frame samples) and starts navigating at time t0 with
  /// the reference point o at the w-frame origin and the given vehicle heading.
  void start(const StaticAccumulator& stat, double vehicle_heading, double t0) override;
  void restart(const Vec3& mean_f_inB, const VehicleFix& fix) override;

  /// One IMU epoch (b-frame sample, see to_body).
  void propagate(const ImuSample& body_sample) override;

  /// This wheel's forward speed from the mean compensated gyro x over the window [m/s].
  double wheel_speed() const;
  double mean_omega_x() const;
  /// d(wheel_speed) / d(b_g,x) and d / d(s_g,x) of this IMU's residual gyro errors.
  struct SpeedSensitivity {
    double dbgx = 0.0, dsgx = 0.0;
  };
  SpeedSensitivity speed_sensitivity() const;
  /// The b-frame x rate this wheel turns at when rolling at `speed` [rad/s].
  double omega_x_at_speed(double speed) const { return -axle_sign_ * speed / module_.wheel_radius; }
  /// This wheel's yaw rate (w-frame z, down: positive turning right) from its gyro less its
  /// spin about the axle [rad/s]: the vehicle's, plus the steering rate of a steered wheel.
  double yaw_rate() const;
  /// The vehicle's yaw rate from this wheel (its own less the steering rate) [rad/s].
  double vehicle_yaw_rate() const { return yaw_rate() - steering_rate(); }
  bool steered() const { return module_.steered; }
  /// A steered wheel's start is over (its steering measured; filter/steering.hpp).
  bool steering_settled() const { return !module_.steered || steer_.settled(); }
  /// The vehicle's heading from another IMU for a steered wheel's start (NaN: none), taken
  /// by the next propagate().
  void set_reference_heading(double heading) { reference_heading_ = heading; }
  /// The steering angle: this wheel's heading less the vehicle's (0 unless steered) [rad].
  double steering() const { return module_.steered ? steer_.angle() : 0.0; }
  double steering_rate() const { return module_.steered ? steer_.rate() : 0.0; }
  /// The vehicle's forward speed (v-frame x) at this wheel's centre: its speed along the wheel
  /// times cos(steering) [m/s]; the same along the whole line parallel to x through it, so
  /// it is also that of the point on the rear axle's line beside it (speed_point_inV()).
  double longitudinal_speed() const { return wheel_speed() * std::cos(steering()); }
  /// Where the vehicle moves at longitudinal_speed() with no side slip: the wheel centre, or
  /// for a steered wheel the point on the rear axle's line beside it (v-frame) [m].
  Vec3 speed_point_inV() const {
    return module_.steered ? Vec3(0.0, module_.p_inV.y(), module_.p_inV.z()) : module_.p_inV;
  }
  /// Forward speed of the wheel centre from the filter's own velocity [m/s].
  double ins_speed() const;
  /// Its velocity measurement noise covariance (Table 9).
  Mat3 velocity_noise() const { return opt_.velocity_std.cwiseAbs2().asDiagonal(); }
  double velocity_gate() const { return opt_.gate; }
  /// The velocity/NHC measurement input (wheel_velocity_model()) with this wheel's own
  /// speed and the current vehicle roll/pitch.
  WheelVelocityInput own_velocity_input() const;
  bool turn_averaging() const { return opt_.turn_average; }
  /// The velocity model and this wheel's speed averaged over the last whole turn, at
  /// the level of `now` (its vehicle roll, pitch); false when off or under one whole turn.
  /// `speed` gets the measured speed fields (set_own_wheel_speed over the same epochs).
  bool turn_averaged(const WheelVelocityInput& now, TurnAverage& out,
                     WheelVelocityInput& speed) const;

  /// Vehicle roll/pitch assumed in the velocity model (0: horizontal-plane assumption;
  /// set by a Body-INS when one shares its attitude).
  void set_vehicle_level(double roll, double pitch) {
    vehicle_roll_ = roll;
    vehicle_pitch_ = pitch;
  }
  double vehicle_heading() const override {
    return wrap_pi(wheel_vehicle_heading(ekf_.state().C_ItoW(), axle_sign_) - steering());
  }
  Eigen::RowVector3d heading_sensitivity() const override;
  Mat3 C_VtoW() const;
  /// Wheel-centre position in the w-frame.
  Vec3 wheel_centre_inW() const;
  /// Eq. (7) through the wheel centre: r_o = r_b + C_b^w l^b - C_v^w r_wc^v.
  ReferencePointInput reference_point_input() const override;
  /// Velocity of o from the wheel-centre velocity and the vehicle yaw rate.
  Vec3 reference_velocity_inW() const override;

 private:
  void begin(const NavState& s, const ImuErrors& e, const InitialUncertainty& init);
  /// A raw axle rate less the estimated bias and scale factor [rad/s].
  double compensated_omega_x(double raw) const;
  WheelInsOptions opt_;
  Mat3 C_StoB_;
  /// The gyro's: C_StoB_ with the wheel-plane axes divided by (1 + yaw_scale).
  Mat3 G_StoB_;
  int axle_sign_;
  double vehicle_roll_ = 0.0, vehicle_pitch_ = 0.0;
  std::array<double, kMaxWindow> window_{};
  int window_len_ = 1, window_count_ = 0, window_pos_ = 0;
  double window_sum_ = 0.0;
  TurnAverager turns_;
  int turns_revision_ = -1;
  SteeringObserver steer_;
  double reference_heading_ = SteeringObserver::kNoHeading;
  Vec3 roll_pivot_ = Vec3::Zero();  // where the IMU was when a steered wheel began to roll
};

}  // namespace wheelins
