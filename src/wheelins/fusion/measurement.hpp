// The fusion's measurements, built once for both filter structures: the wheel
// velocity + NHC of a Wheel-INS (paper eq. 5), the velocity + NHC of the Body-INS
// (eq. 6), and the multi-IMU position constraint (eq. 11, Algorithm 1). Each is one
// Measurement: the innovation, its noise, and H in blocks per IMU. The distributed
// filter fuses the subsystem's own block into that subsystem alone; the centralized
// filter (Section VI-B-2) fuses every block into the joint state (filter_backend.hpp).
//
// What the subsystems share (Section III) is first taken, at one evaluation point,
// into SharedInputs: the Body-INS level, the wheel speeds and their mean, and every
// subsystem's reference point o with their weighted mean (eq. 7, 8). The measurement
// builders read only those and the subsystems' own states.
#pragma once

#include <array>

#include "wheelins/filter/zero_motion.hpp"
#include "wheelins/fusion/subsystems.hpp"

namespace wheelins {

using H3 = Eigen::Matrix<double, 3, kStateDim>;

/// Forward variance of a velocity row that carries no speed [m^2/s^2].
constexpr double kNoSpeedVar = 1e4;

/// One measurement: dz = sum_j H[j] dx_j + e, e ~ N(0, R), with dz = z_hat - z_meas.
struct Measurement {
  int module = -1;          ///< whose measurement it is (the subsystem H_own belongs to)
  int n = 0;                ///< blocks H[0 .. n-1] are valid (one per subsystem)
  Vec3 dz = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  double gate = 0.0;        ///< test-ratio gate; 0 = off
  bool velocity = false;    ///< a velocity + NHC measurement (else the position constraint)
  /// The subsystem's own design matrix, the paper's H_v / H_mlt (Appendix B): the shared
  /// quantities (the other wheels' speeds, the Body-INS level, the fused reference point)
  /// taken as given. What the distributed filter fuses into subsystem `module`.
  H3 H_own = H3::Zero();
  /// d dz / d dx_j for every subsystem j: what the centralized filter fuses. H[module]
  /// differs from H_own where the measurement depends on the subsystem's own state through a
  /// shared quantity (its weight k_i in the reference point of eq. 8).
  std::array<H3, kMaxModules> H;

  /// Starts the measurement of subsystem `i` among `n_subsystems`: every block zero.
  void reset(int i, int n_subsystems) {
    module = i;
    n = n_subsystems;
    velocity = false;
    for (int j = 0; j < n; ++j) H[j].setZero();
  }
};

/// The wheel speeds a velocity-update step uses: speed_ok (usable: in use, not left out by
/// the fault handling) and in_mean (also counted: the speeds that make the mean). `fallback`
/// marks speeds that are only a lower bound (a saturated gyro): used when no other is.
struct SpeedSelection {
  std::array<bool, kMaxModules> speed_ok{}, in_mean{}, fallback{};
  int n_mean = 0;
};

/// What the subsystems share at one evaluation point (Section III).
struct SharedInputs {
  // The vehicle level of the Body-INS (theta_3, phi_3 of eq. 5).
  bool level_shared = false;  ///< a Body-INS shares it (it counts, and sharing is on)
  /// d(roll, pitch) / d phi of the Body-INS (its attitude error), when shared.
  Eigen::Matrix<double, 2, 3> level_sensitivity = Eigen::Matrix<double, 2, 3>::Zero();
  /// Evaluate the Wheel-INS models at the Body-INS level now (level_rpy) instead of the level
  /// each Wheel-INS was last given (WheelIns::set_vehicle_level).
  bool level_now = false;
  Vec3 level_rpy = Vec3::Zero();

  // The wheel speeds (eq. 3) of the velocity-update step.
  /// Each Wheel-INS in use: its velocity input with its own speed (eq. 5), at the level above.
  std::array<WheelVelocityInput, kMaxModules> wheel;
  SpeedSelection speeds;
  double mean_speed = 0.0;          ///< over speeds.in_mean [m/s]
  /// Each Wheel-INS that averages over whole turns (WheelIns::turn_averaged): the model and
  /// its speed over its last whole turns (turn_valid false: off, or under a turn).
  std::array<bool, kMaxModules> turn_valid{};
  std::array<TurnAverage, kMaxModules> turn;
  std::array<WheelVelocityInput, kMaxModules> turn_speed;
  /// The mean of the whole-turn speeds over speeds.in_mean, when every one of them has one.
  bool turn_mean_ok = false;
  double turn_mean_speed = 0.0;
  Vec3 mean_point = Vec3::Zero();   ///< the mean of their wheel centres, v-frame [m]

  // The reference point of the position-constraint step (Algorithm 1).
  std::array<double, kMaxModules> k{};           ///< eq. (8) weights over the counted modules
  std::array<ReferencePointModel, kMaxModules> ref;  ///< every subsystem's o, eq. (7)
  Vec3 fused = Vec3::Zero();                     ///< sum_j k_j r_o^j, eq. (8)
};

/// The level part of `sh`: shared by the Body-INS when `shared` (else not at all); with
/// `now`, the Wheel-INS models use the Body-INS attitude as it is now.
void take_level(const Subsystems& subs, bool shared, bool now, SharedInputs& sh);
/// Every Wheel-INS's velocity input with its own speed (those in `in_use` only).
void take_wheel_inputs(const Subsystems& subs, const std::array<bool, kMaxModules>& in_use,
                       SharedInputs& sh);
/// The selection and the mean speed and wheel point over its in_mean wheels.
void take_mean_speed(const Subsystems& subs, const SpeedSelection& sel, SharedInputs& sh);
/// Every subsystem's reference point o (eq. 7) and their mean with the weights sh.k (eq. 8).
void take_reference(const Subsystems& subs, SharedInputs& sh);

/// The velocity + NHC measurement of subsystem i (eq. 5 for a Wheel-INS, eq. 6 for the
/// Body-INS) under the speed selection of `sh`:
///  - a Wheel-INS uses its own speed, or the mean when sharing the mean (SpeedSharing::kMean)
///    or when its own speed is unusable; without any speed only the NHC rows count;
///  - the Body-INS uses the mean speed at the mean wheel point, or none (NHC only);
///  - a mean speed (1/n) sum_j (-a_j r_j omega_x,j) depends on every Wheel-IMU in it through
///    r delta omega_x of eq. (3): -(1/n) dspeed_j/d(b_g,x, s_g,x) in block j;
///  - a Wheel-INS model depends on the Body-INS attitude through the shared level: H_level
///    times d(roll, pitch)/d(phi_3) in the Body-INS block.
/// With `mean_offset_noise`, a mean speed predicted at one wheel's centre counts that
/// wheel's offset from the mean wheel point as forward noise (see the .cpp).
void velocity_measurement(const Subsystems& subs, const SharedInputs& sh, const FusionOptions& o,
                          int i, bool mean_offset_noise, Measurement& m);

/// The position constraint of subsystem i (eq. 11): dz_i = r_o^i - sum_j k_j r_o^j, which
/// depends on every counted subsystem: (1 - k_i) H_i in block i, -k_j H_j in the others, and
/// through the level a Wheel-INS uses in C_v^w (eq. 7) on the Body-INS attitude. H_own = H_i,
/// the reference taken as an external position (the paper's distributed filter).
void position_measurement(const Subsystems& subs, const SharedInputs& sh, const FusionOptions& o,
                          int i, Measurement& m);

/// The measurements of subsystem i on a standing vehicle (filter/zero_motion.hpp), its own
/// block only (H[i] = H_own): zero velocity of the IMU with sigma `velocity_std`; zero angular
/// rate beyond the earth's, from `mean_raw_rate` (the mean raw b-frame rate over the standstill
/// window of `window` seconds, compensated with the current estimates) with the gyro's white
/// noise over the window and `rate_std` added in quadrature.
void zero_velocity_measurement(const Subsystems& subs, int i, double velocity_std, Measurement& m);
void zero_rate_measurement(const Subsystems& subs, int i, const Vec3& mean_raw_rate, double window,
                           double rate_std, Measurement& m);

}  // namespace wheelins
