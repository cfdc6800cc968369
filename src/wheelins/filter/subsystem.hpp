// What the fusion needs from one IMU's navigation subsystem (Wheel-INS or
// Body-INS): each keeps its own strapdown EKF and exposes the vehicle quantities
// it implies (heading, reference point) with their measurement models.
#pragma once

#include <array>
#include <initializer_list>

#include "wheelins/filter/alignment.hpp"
#include "wheelins/filter/position_constraint.hpp"
#include "wheelins/filter/strapdown_ekf.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

/// What a subsystem does with its yaw-rate scale factor (the gyro axes in a Wheel-IMU's
/// wheel plane, the Body-IMU's axis nearest the vehicle's yaw axis; docs/filter.md 13.4).
enum class YawScaleFactors {
  kHeld,            ///< not estimated (zero covariance); its effect is carried as a consider term
  kFromConstraint,  ///< estimated from the multi-IMU position constraint only: a consider
                    ///< state of the velocity updates (ProcessNoise::velocity_gain)
  kEstimated,       ///< estimated from every update
};

/// The vehicle state a subsystem restarts from after an outage or an isolation
/// (from the other subsystems, or its own extrapolation when it is alone).
struct VehicleFix {
  double t = 0.0;
  Vec3 p_OinW = Vec3::Zero();  ///< reference point o [m]
  Vec3 v_OinW = Vec3::Zero();  ///< velocity of o [m/s]
  double heading = 0.0;        ///< vehicle heading [rad]
  double position_std = 0.1;   ///< [m]
  double velocity_std = 0.3;   ///< [m/s]; also covers the lever-arm velocities left out
  double level_std = 3.0 * kDeg;  ///< roll/pitch from the averaged specific force in motion
  double heading_std = 1.0 * kDeg;
  /// The restart's initial uncertainty.
  InitialUncertainty uncertainty() const {
    InitialUncertainty u;
    u.position = position_std;
    u.velocity = velocity_std;
    u.roll_pitch = level_std;
    u.heading = heading_std;
    return u;
  }
};

/// Mean specific force over a stretch of motion, expressed in the b-frame at its end:
/// each increment is rotated into the first sample's b-frame with the gyro, summed,
/// and the sum rotated to the last one (rotation averages out the centripetal and
/// vibration terms of a spinning wheel).
class MotionAccumulator {
 public:
  void clear() { *this = MotionAccumulator(); }
  void add(const ImuSample& b) {
    C_BnowToB0_ = C_BnowToB0_ * dcm_from_rotvec(b.dtheta);
    sum_dvel_inB0_ += C_BnowToB0_ * b.dvel;
    duration_ += b.dt;
  }
  double duration() const { return duration_; }
  Vec3 mean_f_now() const { return C_BnowToB0_.transpose() * sum_dvel_inB0_ / duration_; }

 private:
  Mat3 C_BnowToB0_ = Mat3::Identity();
  Vec3 sum_dvel_inB0_ = Vec3::Zero();
  double duration_ = 0.0;
};

class Subsystem {
 public:
  Subsystem(const ImuModule& module, const MechanizationOptions& mech)
      : module_(module), mech_(mech), noise_(module.noise) {}
  virtual ~Subsystem() = default;
  Subsystem(const Subsystem&) = delete;
  Subsystem& operator=(const Subsystem&) = delete;

  bool is_wheel() const { return module_.kind == ModuleKind::kWheel; }
  const ImuModule& module() const { return module_; }
  StrapdownEkf& ekf() { return ekf_; }
  const StrapdownEkf& ekf() const { return ekf_; }
  double time() const { return ekf_.state().t; }

  /// Rotates a raw sample from the sensor axes into the subsystem's b-frame.
  virtual ImuSample to_body(const ImuSample& sensor) const = 0;
  /// Aligns from the static mean and starts with o at the w-frame origin.
  virtual void start(const StaticAccumulator& stat, double vehicle_heading, double t0) = 0;
  /// Starts again in motion: level from `mean_f_inB` (the specific force averaged over the
  /// realignment, b-frame now), heading and o from `fix`; the sensor-error estimates are
  /// kept, their uncertainty is reset to the datasheet's.
  virtual void restart(const Vec3& mean_f_inB, const VehicleFix& fix) = 0;
  /// One IMU epoch of b-frame data: the nominal state. The covariance time update is the
  /// fusion filter's (the subsystem's own P, or its block of a joint covariance).
  virtual void propagate(const ImuSample& body_sample) { ekf_.propagate_nominal(body_sample); }
  virtual double vehicle_heading() const = 0;
  /// d(heading)/d(phi), for the heading's 1-sigma.
  virtual Eigen::RowVector3d heading_sensitivity() const = 0;
  /// Inputs of eq. (7) for this subsystem: where it puts the reference point o.
  virtual ReferencePointInput reference_point_input() const = 0;
  /// Vehicle velocity at o in the w-frame.
  virtual Vec3 reference_velocity_inW() const = 0;

  Vec3 reference_point_inW() const { return reference_point_model(reference_point_input()).r_o; }

  /// What is done with the yaw-rate scale factor, and its error states (the mean of their
  /// scale factors is the yaw-rate scale factor): b y, z of a Wheel-IMU, one axis of a Body-IMU.
  YawScaleFactors yaw_scale_factor_mode() const { return yaw_mode_; }
  const std::array<int, 2>& yaw_scale_factor_states() const { return yaw_states_; }
  int yaw_scale_factor_state_count() const { return yaw_count_; }
  /// The variance of the yaw-rate scale factor under the covariance P: the mean of its states'
  /// block where they are estimated; held, the noise model's gyro_sf_std^2 over the number of
  /// axes (independent); 0 without yaw states.
  double yaw_scale_factor_variance(const Mat21& P) const {
    if (yaw_count_ == 0) return 0.0;
    if (yaw_mode_ == YawScaleFactors::kHeld) return noise_.gyro_sf_std * noise_.gyro_sf_std / yaw_count_;
    double v = 0.0;
    for (int a = 0; a < yaw_count_; ++a)
      for (int b = 0; b < yaw_count_; ++b) v += P(yaw_states_[a], yaw_states_[b]);
    return v / (yaw_count_ * yaw_count_);
  }

  /// The noise model in use: the module's figures, as the noise identification has set them
  /// since (fusion/noise_adaptation.hpp), and which states are estimated. Restarts keep it.
  const ProcessNoise& process_noise() const { return noise_; }
  /// New figures from here on (the estimated states stay as they are).
  void set_process_noise(const ImuNoise& q) {
    static_cast<ImuNoise&>(noise_) = q;
    ekf_.set_noise(noise_);
  }

 protected:
  /// Applies `mode` to the error states `yaw_states` (the yaw-rate scale factor's) in the
  /// noise model: held (not estimated), or a consider state of the velocity updates.
  void set_yaw_scale_factor_mode(YawScaleFactors mode, std::initializer_list<int> yaw_states) {
    yaw_mode_ = mode;
    yaw_count_ = 0;
    for (int k : yaw_states) {
      if (mode == YawScaleFactors::kHeld) noise_.estimated(k) = 0.0;
      if (mode == YawScaleFactors::kFromConstraint) noise_.velocity_gain(k) = 0.0;
      if (yaw_count_ < 2) yaw_states_[yaw_count_++] = k;
    }
  }

  ImuModule module_;
  MechanizationOptions mech_;
  ProcessNoise noise_;
  StrapdownEkf ekf_;
  YawScaleFactors yaw_mode_ = YawScaleFactors::kHeld;
  std::array<int, 2> yaw_states_{};
  int yaw_count_ = 0;
};

}  // namespace wheelins
