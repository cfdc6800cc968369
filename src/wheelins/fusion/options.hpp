// The navigator's settings (every filter and fusion option, in SI units), their
// human-readable listing and their checks, and the counters a run reports.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "wheelins/filter/body_ins.hpp"
#include "wheelins/filter/wheel_ins.hpp"
#include "wheelins/fusion/fault_monitor.hpp"

namespace wheelins {

/// The most IMUs one navigator fuses.
constexpr int kMaxModules = 16;

/// How the Wheel-INSs get their forward speed.
enum class SpeedSharing {
  kMean,  ///< the paper: the mean of all Wheel-IMU speeds, for every subsystem
  kOwn,   ///< each Wheel-INS its own wheel's speed; a Body-INS the mean, at the mean wheel point
};

/// The yaw-rate scale factors of every subsystem (docs/filter.md 13.4).
enum class YawScaleFactorChoice {
  /// From the position constraint where a Body-IMU's heading takes part in it (the constraint
  /// on, over a Body-IMU and at least one Wheel-IMU); held otherwise.
  kAuto,
  kHeld,            ///< YawScaleFactors::kHeld everywhere
  kFromConstraint,  ///< YawScaleFactors::kFromConstraint everywhere
  kEstimated,       ///< YawScaleFactors::kEstimated everywhere
};

/// Where the reference weights k_i of eq. (8) come from.
enum class ReferenceWeighting {
  kFixed,       ///< FusionOptions::weights (empty: equal), the paper
  kCovariance,  ///< each subsystem's own uncertainty of o: inverse variance (aids/position_constraint/reference_weights.hpp)
  /// Each subsystem's drift on its own, without the constraint: the inverse of the lateral
  /// variance of its constraint-free heading model (a federated filter's no-reset weights;
  /// StandaloneDrift in aids/position_constraint/reference_weights.hpp). A Body-IMU's unmodulated yaw bias counts.
  kStandalone,
};

struct FusionOptions {
  /// Own by default: the mean is off by +-omega_yaw * track / 2 at each wheel in a turn, an
  /// error that follows the turns like a yaw-rate scale factor (docs/filter.md section 9).
  SpeedSharing speed = SpeedSharing::kOwn;
  bool share_level = true;                ///< Body-INS roll/pitch to the Wheel-INSs
  bool position_constraint = true;
  double position_update_interval = 1.0;  ///< [s]; the paper's 1 Hz
  double position_std = 0.2;              ///< [m] (Table 9)
  double position_gate = 0.0;             ///< test-ratio gate; 0 = off
  std::vector<double> weights;            ///< k_i of eq. (8); empty = equal
  ReferenceWeighting weighting = ReferenceWeighting::kFixed;
  /// kCovariance: constraint epochs the variances are averaged over (e-folding).
  double weight_window = 60.0;
  /// [s] e-folding window of each subsystem's heading offset to the mean heading of all
  /// (OutputFusion::heading_offset): what carries the fused heading through an outage.
  double heading_offset_window = 30.0;
  /// One joint covariance over all IMUs (Section VI-B-2) instead of one per subsystem.
  bool centralized = false;
  /// A steered wheel's reference point o and heading rest on its estimated steering angle,
  /// whose errors (tyre slip angles, caster, toe) nothing models: false (the default) ties it
  /// to the vehicle without letting it make the reference of eq. (8) or the output while a
  /// Wheel-IMU that does not steer counts (Subsystems::follows); true counts it as any other.
  bool steered_in_reference = false;
};

/// The noise model learned from the data (noise_adaptation.hpp, docs/filter.md section 13).
struct NoiseAdaptationOptions {
  bool enabled = true;            ///< false: the given figures are held fixed (only reported)
  double window = 60.0;           ///< velocity updates the in-motion estimates weigh (e-folding)
  double r_floor_fraction = 0.5;  ///< measurement noise never below this share of its given sigma
  double vrw_max = 20.0 / 60.0;   ///< [m/s/sqrt(s)]
  double min_speed = 0.2;         ///< [m/s]: at rest speed and constraints are exact, not noisy
  double settle = 10.0;           ///< [s] after a start before innovations count
  double bias_floor = 5.0 * kDeg / 3600.0;  ///< Wheel-IMU gyro bias instability floor [rad/s]
  void validate() const;
};

/// Zero-velocity detection while the vehicle stands (aids/zero_motion/standstill.hpp, docs/faults.md).
struct StandstillOptions {
  bool enabled = true;
  double max_rate = 1.0 * kDeg;     ///< [rad/s] every IMU's compensated rate (block means) below
  double max_force_spread = 0.3;    ///< [m/s^2] block means of the specific force, max - min per axis
  double block = 0.05;              ///< [s] the blocks the means are taken over
  double min_time = 1.0;            ///< [s] quiet this long before the vehicle stands
  double velocity_std = 0.01;       ///< [m/s] the zero-velocity measurement's sigma
  double rate_std = 0.05 * kDeg;    ///< [rad/s] the zero-rate sigma (with the gyro noise of the window)
  void validate() const;
};

struct NavigatorOptions {
  /// The Wheel-INS and Body-INS settings; their yaw_scale_factors are set from
  /// `yaw_scale_factors` by resolved().
  WheelInsOptions wheel;
  BodyInsOptions body;
  FusionOptions fusion;
  YawScaleFactorChoice yaw_scale_factors = YawScaleFactorChoice::kAuto;
  MechanizationOptions::Method mechanization = MechanizationOptions::Method::kRotationExact;
  /// Compensate the earth rotation (the manifest says whether the data contain it).
  bool earth_rotation = true;
  /// Sensor-fault handling: outages, saturation, slip, isolation of faulty IMUs.
  FaultOptions faults;
  /// Noise identification from the data (off: the given figures held fixed).
  NoiseAdaptationOptions noise;
  /// Zero-velocity and zero-rate updates while the vehicle stands.
  StandstillOptions standstill;
  /// Output interval [s]; 0 = every epoch of the first module.
  double output_interval = 0.0;
  /// Also send each subsystem's own solution to the sink (streams 1..N) of a multi-IMU run.
  bool module_records = true;
  /// Covariance time update every this many seconds, F integrated over the epochs in
  /// between (StrapdownEkf::set_covariance_interval); 0 = every IMU epoch. Measurement
  /// updates always see P propagated to their epoch. At most kMaxCovarianceInterval.
  double covariance_interval = 0.05;
  static constexpr double kMaxCovarianceInterval = 0.5;  ///< [s]
  /// These options for a navigator over `n_modules` modules, `has_body` when one is a
  /// Body-IMU: wheel/body.yaw_scale_factors set from `yaw_scale_factors` (kAuto decided here).
  NavigatorOptions resolved(int n_modules, bool has_body) const;
  /// Throws InputError naming the option if a value is out of range (the fault options
  /// are checked by FaultOptions::validate()).
  void validate() const;
};

/// Counters and timing of a run.
struct NavigatorStats {
  std::uint64_t samples = 0;            ///< samples given to process()
  std::uint64_t epochs = 0;             ///< navigation epochs of the first module
  std::uint64_t velocity_updates = 0;   ///< per subsystem, summed
  std::uint64_t velocity_rejected = 0;  ///< refused by the innovation gate
  std::uint64_t position_updates = 0;
  std::uint64_t position_rejected = 0;
  std::uint64_t records = 0;
  /// Velocity-update steps at which the vehicle stood (zero velocity and rate fused instead),
  /// and those updates.
  std::uint64_t standstill_steps = 0, zero_motion_updates = 0;
  double t_start = 0.0, t_end = 0.0;    ///< navigation interval [s]
  double max_velocity_test_ratio = 0.0;
  double max_position_test_ratio = 0.0;
  /// Time spent in the velocity-update and position-constraint steps (all subsystems) and
  /// their number of occurrences, for the paper's Table 8 [s].
  double velocity_step_seconds = 0.0, position_step_seconds = 0.0;
  std::uint64_t velocity_steps = 0, position_steps = 0;
  /// Covariance health, checked at every velocity-update step for every subsystem in use:
  /// checks, failures of the Cholesky test (not positive definite), and the largest
  /// asymmetry max|P - P^T| / max|P| seen.
  std::uint64_t covariance_checks = 0, covariance_not_pd = 0;
  double max_covariance_asymmetry = 0.0;
};

}  // namespace wheelins
