// One IMU's navigation filter: strapdown mechanization predicting the nominal
// state, the 21-state error-state EKF (paper Section IV-B) tracking its
// uncertainty, and error feedback after each update. Wheel-INS and Body-INS
// are built on it; each measurement model lives in its own file.
#pragma once

#include "wheelins/filter/ekf_update.hpp"
#include "wheelins/filter/error_model.hpp"
#include "wheelins/nav/mechanization.hpp"

namespace wheelins {

/// 1-sigma of the initial state (SI).
struct InitialUncertainty {
  double position = 0.01;             ///< [m]
  double velocity = 0.01;             ///< [m/s]
  double roll_pitch = 0.1 * kDeg;     ///< [rad]
  double heading = 0.1 * kDeg;        ///< [rad]
};

class StrapdownEkf {
 public:
  StrapdownEkf() = default;
  /// Starts navigating from `state` with estimated sensor errors `errors`.
  void initialize(const NavState& state, const ImuErrors& errors, const ProcessNoise& noise,
                  const InitialUncertainty& init, const MechanizationOptions& mech);

  /// One IMU epoch: compensate, mechanize, propagate the covariance. `raw` is in the
  /// IMU b-frame (mounting already applied), as increments.
  void propagate(const ImuSample& raw) {
    propagate_nominal(raw);
    if (own_covariance_) propagate_covariance(P_, dyn_, noise_, last_.dt);
  }
  /// A centralized filter keeps the covariance: propagate() then skips this one's P.
  void set_external_covariance(bool external) { own_covariance_ = !external; }
  /// The nominal part only (compensation, mechanization, F of this epoch); a
  /// centralized filter propagates the joint covariance itself.
  void propagate_nominal(const ImuSample& raw);
  /// The blocks of F of the last epoch (at the propagated state).
  const ErrorDynamics& last_dynamics() const { return dyn_; }
  const ProcessNoise& noise() const { return noise_; }

  /// Fuses a measurement (dz = z_hat - z_meas = H dx + e) and feeds the error back.
  template <int M>
  UpdateReport update(const Eigen::Matrix<double, M, kStateDim>& H,
                      const Eigen::Matrix<double, M, 1>& dz, const Eigen::Matrix<double, M, M>& R,
                      double gate = 0.0) {
    Vec21 dx = Vec21::Zero();
    const UpdateReport rep = ekf_update<M>(P_, dx, H, dz, R, gate);
    if (rep.accepted) feedback(dx);
    return rep;
  }

  const NavState& state() const { return state_; }
  const ImuErrors& errors() const { return errors_; }
  const Mat21& covariance() const { return P_; }
  Mat21& covariance() { return P_; }
  /// The last sample compensated with the current error estimates, as rates [rad/s],
  /// [m/s^2] (after a feedback, the corrected estimates apply: measurement models evaluated
  /// between two epochs, e.g. a centralized filter's sequential updates, stay consistent).
  Vec3 omega_ib_b() const { return compensate(last_raw_, errors_).dtheta / last_raw_.dt; }
  Vec3 f_b() const { return last_.dvel / last_.dt; }
  const ImuSample& last_compensated() const { return last_; }
  const MechanizationOptions& mechanization() const { return mech_; }
  bool initialized() const { return initialized_; }

  /// Applies an error estimate (position, velocity, attitude, sensor errors) to the state.
  void feedback(const Vec21& dx);
  /// Replaces the sensor-error estimates (e.g. with earlier ones after a fault).
  void set_errors(const ImuErrors& e) { errors_ = e; }

 private:
  NavState state_;
  ImuErrors errors_;
  Mat21 P_ = Mat21::Zero();
  ErrorDynamics dyn_;
  ProcessNoise noise_;
  MechanizationOptions mech_;
  ImuSample last_;
  ImuSample last_raw_;
  bool have_last_ = false;
  bool initialized_ = false;
  bool own_covariance_ = true;
};

}  // namespace wheelins
