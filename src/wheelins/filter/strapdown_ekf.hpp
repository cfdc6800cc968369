// One IMU's navigation filter: strapdown mechanization predicting the nominal
// state, the 21-state error-state EKF (paper Section IV-B) tracking its
// uncertainty, and error feedback after each update. Wheel-INS and Body-INS
// are built on it; each measurement model lives in its own file.
#pragma once

#include <array>

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

  /// One IMU epoch of a stand-alone filter: compensate, mechanize, and accumulate F; the
  /// covariance is propagated once `covariance_interval` has passed (see
  /// set_covariance_interval). `raw` is in the IMU b-frame (mounting already applied), as
  /// increments. (In the navigator the fusion filter owns the time update: the subsystems
  /// propagate the nominal state only, fusion/filter_backend.hpp.)
  void propagate(const ImuSample& raw) {
    propagate_nominal(raw);
    if (covariance_due()) flush_covariance();
  }
  /// The nominal part only (compensation, mechanization, F of this epoch accumulated).
  void propagate_nominal(const ImuSample& raw);

  /// Covariance time update at a lower rate than the mechanization: the blocks of F are
  /// integrated over the epochs of `interval` seconds and P is propagated once with their
  /// mean F in Phi = I + F T + (F T)^2 / 2 (eq. 2 discretized over the interval T; C_b^w of
  /// a spinning wheel is integrated, not sampled; see apply_transition for the order).
  /// 0 = every epoch. Every measurement
  /// update first propagates P to the current epoch.
  void set_covariance_interval(double interval) { covariance_interval_ = interval; }
  double covariance_interval() const { return covariance_interval_; }
  /// The accumulated dynamics are due for a covariance propagation.
  bool covariance_due() const { return pending_dt_ + 1e-9 >= covariance_interval_; }
  /// Propagates the own P over the accumulated epochs (no-op if none).
  void flush_covariance();
  /// The accumulated F blocks averaged over pending_dt() (for a joint covariance that
  /// propagates this IMU's block itself, fusion/centralized.hpp).
  ErrorDynamics pending_dynamics() const;
  double pending_dt() const { return pending_dt_; }
  void clear_pending();
  const ProcessNoise& noise() const { return noise_; }
  /// New noise figures from here on (noise identification, fusion/noise_adaptation.hpp): the
  /// white noise densities and Gauss-Markov sigmas; which states are estimated stays as
  /// initialize() set it.
  void set_noise(const ProcessNoise& noise);
  /// The gyro-bias uncertainty after the alignment (its accuracy, from the static data),
  /// uncorrelated with the other states; only before the first update.
  void set_gyro_bias_uncertainty(double sigma);

  /// Fuses a measurement (dz = z_hat - z_meas = H dx + e) and feeds the error back.
  template <int M>
  UpdateReport update(const Eigen::Matrix<double, M, kStateDim>& H,
                      const Eigen::Matrix<double, M, 1>& dz, const Eigen::Matrix<double, M, M>& R,
                      double gate = 0.0, const Vec21* gain_mask = nullptr) {
    flush_covariance();
    Vec21 dx = Vec21::Zero();
    Eigen::Matrix<double, kStateDim, M> K;
    const UpdateReport rep = ekf_update<M>(P_, dx, H, dz, R, gate, &K, gain_mask);
    if (rep.accepted) {
      feedback(dx);
      // The held states' effect on the estimated ones, through this update (H S includes
      // their own columns of H: S has a 1 in each held state's row).
      if (n_held_) S_ -= K * (H * S_);
      reported_dirty_ = true;
    }
    return rep;
  }

  /// Consider analysis of the held states (docs/filter.md section 13.4): their prior
  /// uncertainty does not enter the gains, but what it does to the estimated states is
  /// carried in the sensitivity S = d(error)/d(held state value), propagated by the same Phi
  /// and updated by the same gains. The covariance to report (and to test against the
  /// truth) is P + S diag(sigma_held^2) S^T; the held states' own rows and columns are
  /// theirs.
  const Mat21& reported_covariance() const;
  static constexpr int kMaxHeld = 3;
  int held_count() const { return n_held_; }
  const Eigen::Matrix<double, kStateDim, kMaxHeld>& held_sensitivity() const { return S_; }
  /// The prior variances of the held states (the columns of S).
  const Eigen::Matrix<double, kMaxHeld, 1>& held_variance() const { return held_var_; }
  const std::array<int, kMaxHeld>& held_states() const { return held_; }

  const NavState& state() const { return state_; }
  const ImuErrors& errors() const { return errors_; }
  /// P as of the last covariance propagation (at most covariance_interval() old; call
  /// flush_covariance() first for P at the current epoch). Read-only: an accessor that
  /// propagated P as a side effect made every read through a non-const path a time update.
  const Mat21& covariance() const { return P_; }
  /// The last sample compensated with the current error estimates, as rates [rad/s],
  /// [m/s^2] (after a feedback, the corrected estimates apply: measurement models evaluated
  /// between two epochs, e.g. a centralized filter's sequential updates, stay consistent).
  /// Zero before the first epoch (no sample yet: 0 / 0 gave the first record a NaN velocity).
  Vec3 omega_ib_b() const {
    return last_raw_.dt > 0.0 ? Vec3(compensate(last_raw_, errors_).dtheta / last_raw_.dt) : Vec3::Zero();
  }
  Vec3 f_b() const { return last_.dvel / last_.dt; }
  const ImuSample& last_compensated() const { return last_; }
  const MechanizationOptions& mechanization() const { return mech_; }
  bool initialized() const { return initialized_; }
  /// How many times initialize() ran (a restart starts the filter again).
  int starts() const { return starts_; }

  /// Applies an error estimate (position, velocity, attitude, sensor errors) to the state.
  void feedback(const Vec21& dx);
  /// Turns the navigation state by `angle` about the w-frame's vertical through `pivot`
  /// (attitude, velocity, and the position's offset from the pivot); a steered wheel's start
  /// (filter/steering.hpp). The covariance is kept (the turn comes within a metre of travel,
  /// where the position's and velocity's are level-isotropic to first order).
  void rotate_about_vertical(double angle, const Vec3& pivot);
  /// Replaces the sensor-error estimates (e.g. with earlier ones after a fault).
  void set_errors(const ImuErrors& e) {
    errors_ = e;
    ++revision_;
  }
  /// The sum of every correction fed back since the last initialize() (to first order: the
  /// attitude parts add as rotation vectors). A model evaluated at an earlier epoch is brought
  /// to the current estimates by -H (total now - total then) (filter/turn_average.hpp).
  const Vec21& feedback_total() const { return feedback_total_; }
  /// Changes when the estimates change other than by feedback (initialize(), set_errors()):
  /// models kept from before are not comparable any more.
  int revision() const { return revision_; }

 private:
  NavState state_;
  ImuErrors errors_;
  Mat21 P_ = Mat21::Zero();
  ErrorDynamics pending_;      ///< sum of F's blocks * dt since the last propagation
  double pending_dt_ = 0.0;
  double covariance_interval_ = 0.0;
  ProcessNoise noise_;
  MechanizationOptions mech_;
  ImuSample last_;
  ImuSample last_raw_;
  bool have_last_ = false;
  bool initialized_ = false;
  int starts_ = 0;
  int revision_ = 0;
  Vec21 feedback_total_ = Vec21::Zero();
  // Consider analysis of the held states (reported_covariance).
  Eigen::Matrix<double, kStateDim, kMaxHeld> S_ = Eigen::Matrix<double, kStateDim, kMaxHeld>::Zero();
  Eigen::Matrix<double, kMaxHeld, 1> held_var_ = Eigen::Matrix<double, kMaxHeld, 1>::Zero();
  std::array<int, kMaxHeld> held_{};
  int n_held_ = 0;
  mutable Mat21 reported_ = Mat21::Zero();  ///< cache of reported_covariance()
  mutable bool reported_dirty_ = true;
};

/// The prior variance a held state stands for (its noise figure squared).
double held_state_variance(const ProcessNoise& q, int k);

}  // namespace wheelins
