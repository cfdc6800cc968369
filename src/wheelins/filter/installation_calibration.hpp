// Installation calibration of a Wheel-IMU from its own data (docs/filter.md section 15):
// the axle direction in its frame (the mounting pitch and yaw) and its lever arm to the
// wheel centre, estimated by a recursive accumulator in front of the filter.
//
// Both quantities show in the data averaged over whole wheel turns, taken by angle (each
// sample weighted by the angle it turns through), where everything that turns with the
// wheel cancels: gravity, the vehicle's acceleration and its yaw rate seen from the wheel.
//  * Axle: the rotation vector of a turn is 2 pi times the spin axis (the mean spin axis of
//    Chen et al. 2019, the paper's ref. chen2019): summed over all turns, its direction in
//    the b-frame given by the manifest is the axle. Its component about the axle itself
//    (the mounting roll) is a wheel-angle offset: unobservable and without effect.
//  * Lever arm: the accelerometer at r = -l from the wheel centre reads, per turn, in the
//    axle-perpendicular plane (b y, z), the centripetal and tangential terms
//      f_y = c l_y + s l_z + b_y,   f_z = c l_z - s l_y + b_z,
//    c the turn's mean omega_x^2, s its mean angular acceleration, b the accelerometer bias.
//    The bias is taken as constant over a chunk of `chunk_s` and eliminated per chunk (the
//    regressors centred within the chunk), so a drifting bias does not leak into l; l is
//    observable where the wheel speed varies within chunks (stops, corners). l_x (along
//    the axle) gives no term: unobservable and without effect on the wheel velocity.
//  * Relative wheel radii (two Wheel-IMUs on either side of the vehicle): over time bins
//    of `rate_bin_s`, the vehicle yaw rate that the wheels themselves see (each
//    Wheel-IMU's in-plane rate projected on the down direction its accelerometer shows,
//    psi_dot = -(w_y f_y + w_z f_z) / g: gravity turns with the wheel exactly as the yaw
//    rate does, so the product does not) against the wheels' speed difference,
//      track psi_dot = r_L w_L - r_R w_R,
//    fitted for eps_L - eps_R (the radii's relative errors) and a scale of psi_dot.
//    estimate_relative_radius() combines two sides' series.
//  * A Body-IMU's mounting: roll and pitch from the axis the vehicle turns about
//    (BodyImuCalibrator), the yaw from its lateral specific force against the Wheel-IMUs'
//    axle accelerometers (estimate_body_yaw()).
// Each estimate is combined with a Gaussian prior around the manifest value; with no
// information it stays there and says so (observed = false).
//
// Per sample: fixed-size arithmetic, no allocation (the time-bin series are reserved for
// the expected duration up front).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "wheelins/nav/types.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

struct InstallationCalibrationOptions {
  double lever_arm_prior_std = 0.01;      ///< 1 sigma of the manifest lever arm [m]
  double mounting_prior_std = 1.0 * kDeg; ///< 1 sigma of the manifest axle direction [rad]
  double min_spin_rate = 1.0;             ///< a turn counts only while |omega_x| exceeds this [rad/s]
  double chunk_s = 60.0;                  ///< the accelerometer bias is constant within [s]
  int min_turns = 20;                     ///< fewer whole turns: nothing is estimated
  /// An estimate is "observed" when the data shrink the prior sigma below this fraction.
  double observed_ratio = 0.5;
  double rate_bin_s = 1.0;                ///< time bins of the relative-radius fit [s]
  double radius_prior_std = 0.01;         ///< 1 sigma of the manifest radii's ratio [-]
  double body_mounting_prior_std = 1.0 * kDeg;  ///< 1 sigma of a Body-IMU's manifest mounting
  double position_prior_std = 0.02;       ///< 1 sigma of a Body-IMU's manifest position relative to the wheels [m]
  double min_yaw_rate = 0.1;              ///< a Body-IMU counts as turning above this [rad/s]
  double yaw_bin_s = 0.1;                 ///< time bins of a Body-IMU's yaw fit [s]
};

/// An estimate with its 1-sigma and whether the data determined it.
struct CalibratedValue {
  double value = 0.0;
  double std = 0.0;
  bool observed = false;
};

struct WheelImuCalibration {
  std::string module;
  int turns = 0;                 ///< whole wheel turns used
  double spin_angle = 0.0;       ///< total angle turned through while rolling [rad]
  /// The axle-direction correction: the small rotation about b y and b z (b-frame of the
  /// manifest mounting) that carries the measured spin axis onto b x [rad].
  CalibratedValue axle_tilt_y, axle_tilt_z;
  /// The mounting angles with the correction applied (roll kept: unobservable) [rad].
  Vec3 mounting_rpy = Vec3::Zero();
  Vec3 manifest_mounting_rpy = Vec3::Zero();
  /// The lever arm in the corrected b-frame (x kept: unobservable) [m].
  CalibratedValue lever_arm[3];
  Vec3 manifest_lever_arm = Vec3::Zero();
  double accel_residual_rms = 0.0;  ///< per-turn residual of the lever-arm fit [m/s^2]
  /// The wheel radius relative to the Wheel-IMU(s) on the other side of the vehicle: the
  /// radius with the relative correction applied (the two sides' mean kept at the
  /// manifest's; the absolute radius is not observable), its 1 sigma [m]. Without a
  /// Wheel-IMU on the other side: the manifest's radius, not observed.
  CalibratedValue wheel_radius;
  double manifest_wheel_radius = 0.0;

  Vec3 lever_arm_inB() const { return {lever_arm[0].value, lever_arm[1].value, lever_arm[2].value}; }
};

/// The time bins that hold data, in index order (bin k: [k, k + 1) bin widths from the end
/// of the static period). Only bins with samples are kept, so the memory is in proportion
/// to the data whatever its time span: a clock in the wrong unit, or a gap of years, costs
/// one bin per bin of data, never the bins between.
template <class Bin>
class BinSeries {
 public:
  struct Entry {
    std::size_t index = 0;
    Bin bin{};
  };
  /// The bin of `index`, added if new (appended when samples come in time order).
  Bin& at(std::size_t index) {
    if (entries_.empty() || entries_.back().index < index) {
      entries_.push_back(Entry{index, Bin{}});
      return entries_.back().bin;
    }
    auto it = lower(index);
    if (it == entries_.end() || it->index != index) it = entries_.insert(it, Entry{index, Bin{}});
    return it->bin;
  }
  /// The bin of `index`; null when it holds no data.
  const Bin* find(std::size_t index) const {
    const auto it = const_cast<BinSeries*>(this)->lower(index);
    return it == entries_.end() || it->index != index ? nullptr : &it->bin;
  }
  const std::vector<Entry>& entries() const { return entries_; }
  /// One past the last bin's index (0 when empty).
  std::size_t end_index() const { return entries_.empty() ? 0 : entries_.back().index + 1; }
  void reserve(std::size_t n) { entries_.reserve(n); }

 private:
  typename std::vector<Entry>::iterator lower(std::size_t index) {
    return std::lower_bound(entries_.begin(), entries_.end(), index,
                            [](const Entry& e, std::size_t k) { return e.index < k; });
  }
  std::vector<Entry> entries_;
};

/// Sums over one time bin of a Wheel-IMU's data (bins from the end of the static period).
struct RateBin {
  double dt = 0.0;    ///< sampled time in the bin [s]
  double spin = 0.0;  ///< forward wheel angle, -axle_sign * integral of w_x [rad]
  double wf = 0.0;    ///< integral of w_y f_y + w_z f_z [rad m/s^2]
  double w_y = 0.0, w_z = 0.0, f_y = 0.0, f_z = 0.0;  ///< their integrals
  double cos_a = 0.0, sin_a = 0.0;  ///< integrals of the wheel angle's cosine and sine
  /// The vehicle yaw rate the wheel sees over the bin [rad/s]: the in-plane rate on the
  /// down direction -f / g, from the bin's covariance of w and f, so that what is constant
  /// in the b-frame (a mounting error's share of the spin, the centripetal term of the
  /// lever arm, biases) does not multiply into a rate. The down direction turns with the
  /// wheel; over a bin that is not a whole number of turns its covariance with itself is
  /// 1 - |m|^2, m its mean over the bin: divided out. NaN where the wheel turned too
  /// little for a rate (|m|^2 > 0.8).
  double yaw_rate(double g) const {
    if (!(dt > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    const double spread = 1.0 - (cos_a * cos_a + sin_a * sin_a) / (dt * dt);
    if (spread < 0.2) return std::numeric_limits<double>::quiet_NaN();
    return -(wf - (w_y * f_y + w_z * f_z) / dt) / (g * dt * spread);
  }
};

/// The specific force of a Wheel-IMU over one time bin of a Body-IMU's yaw fit (bins of
/// `yaw_bin_s` from the end of the static period).
struct AxleBin {
  double dt = 0.0;        ///< sampled time in the bin [s]
  Vec3 f = Vec3::Zero();  ///< integral of the specific force in the manifest b-frame [m/s]
};

/// The sums over the static period before the run: its mean rate is the gyro bias, its
/// mean specific force gravity as the accelerometer reads it.
struct StaticPeriodSums {
  double start = 0.0, end = 0.0;
  Vec3 dtheta = Vec3::Zero(), dvel = Vec3::Zero();
  double dt = 0.0;
  /// True for a sample at or before the static period's end (counted if inside it).
  bool take(const ImuSample& s) {
    if (s.t > end) return false;
    if (s.t > start) {
      dtheta += s.dtheta;
      dvel += s.dvel;
      dt += s.dt;
    }
    return true;
  }
  Vec3 gyro_bias() const { return dt > 0.0 ? Vec3(dtheta / dt) : Vec3::Zero(); }
  /// The white-noise part of the bias estimate's 1 sigma [rad/s].
  double gyro_bias_noise(double arw) const { return dt > 0.0 ? arw / std::sqrt(dt) : 0.0; }
  double gravity() const { return dt > 0.0 ? std::max(1.0, dvel.norm() / dt) : 9.8; }
};

class WheelImuCalibrator {
 public:
  /// `static_start`, `static_end`: the static period, whose mean rate is the gyro bias.
  /// `expected_end`: the time of the last sample if known (the rate series is reserved up
  /// to it; later samples still count).
  WheelImuCalibrator(const ImuModule& module, double static_start, double static_end,
                     const InstallationCalibrationOptions& opt = {}, double expected_end = 0.0);

  /// One raw sample in the sensor axes (as read from the module's file), in time order.
  void add(const ImuSample& sensor_sample);

  /// The estimates from the data so far (cheap; may be called at any time).
  WheelImuCalibration result() const;

  int turns() const { return turns_; }
  const ImuModule& module() const { return module_; }
  const BinSeries<RateBin>& rate_bins() const { return bins_; }
  const BinSeries<AxleBin>& axle_bins() const { return axle_bins_; }
  /// |f| over the static period (gravity as this accelerometer reads it) [m/s^2].
  double gravity() const { return static_.gravity(); }

 private:
  struct TurnSums {  // angle-weighted sums over the current turn
    double angle = 0.0, dt = 0.0, c = 0.0, s = 0.0;
    Vec3 f = Vec3::Zero(), rot = Vec3::Zero();
  };
  struct RegressionSums {  // sums over turns of the per-turn means
    double n = 0.0, c = 0.0, s = 0.0, cc = 0.0, ss = 0.0;
    Vec3 m = Vec3::Zero(), cm = Vec3::Zero(), sm = Vec3::Zero();
    Mat3 mm = Mat3::Zero();
  };
  void close_turn(int phase);
  void close_chunk();
  void reset_turns() {
    for (auto& t : turn_) t = TurnSums{};
    sequence_angle_ = 0.0;
  }
  /// Turns are taken at this many phases of the wheel, evenly spaced: the part of the
  /// vehicle's acceleration that changes within a turn leaves a residual that depends on
  /// where the turn starts, and it cancels over the phases.
  static constexpr int kPhases = 8;

  ImuModule module_;
  InstallationCalibrationOptions opt_;
  Mat3 C_StoB_;
  StaticPeriodSums static_;
  double prev_wx_ = 0.0;
  bool have_prev_ = false;
  int spin_sign_ = 0;
  double chunk_start_ = 0.0;
  double t_ = 0.0;

  TurnSums turn_[kPhases];
  double sequence_angle_ = 0.0;  ///< angle turned since the wheel last started rolling
  RegressionSums chunk_;
  // Centred (within-chunk) sums over all closed chunks.
  double Scc_ = 0.0, Sss_ = 0.0, chunks_ = 0.0, rows_ = 0.0;
  Vec3 Scm_ = Vec3::Zero(), Ssm_ = Vec3::Zero();
  Mat3 Smm_ = Mat3::Zero();
  // Axle: the summed rotation vectors and the scatter of the per-turn directions.
  Vec3 axle_sum_ = Vec3::Zero(), dir_sum_ = Vec3::Zero();
  Vec3 dir_sq_ = Vec3::Zero();  // per-axis sums of squares
  int turns_ = 0;
  double spin_angle_ = 0.0, rolling_time_ = 0.0;
  // Relative radius: the rate series.
  double wheel_angle_ = 0.0;
  BinSeries<RateBin> bins_;
  BinSeries<AxleBin> axle_bins_;  // a Body-IMU's yaw fit
};

/// Sums over one time bin of a Body-IMU's data (the bins of AxleBin), in the v-frame given
/// by the manifest mounting.
struct BodyBin {
  double dt = 0.0;       ///< sampled time in the bin [s]
  Vec3 w = Vec3::Zero(); ///< integral of the rate, static-period bias removed [rad]
  Vec3 f = Vec3::Zero(); ///< integral of the specific force [m/s]
};

/// A Body-IMU's mounting against the vehicle frame (C_b^v as ZYX Euler angles).
struct BodyImuCalibration {
  std::string module;
  double turning_time = 0.0;  ///< time spent turning faster than min_yaw_rate [s]
  /// The correction of the vehicle's z-axis (the yaw axis) as seen in the v-frame given by
  /// the manifest: small rotations about v x and v y [rad].
  CalibratedValue tilt_x, tilt_y;
  /// The correction of the mounting yaw: a rotation about v z, after the tilt [rad]; from
  /// the lateral specific force against the Wheel-IMUs' axle accelerometers
  /// (estimate_body_yaw(); without a Wheel-IMU in the run: the manifest's, not observed).
  CalibratedValue yaw;
  /// Fitted with the yaw: the correction of the Body-IMU's position in the v-frame (x, y)
  /// relative to the mean of the Wheel-IMUs' manifest positions [m], so that the offset
  /// between them is the true one.
  CalibratedValue position_x, position_y;
  Vec3 manifest_position = Vec3::Zero();  ///< the manifest's position_v_m [m]
  int yaw_bins = 0;                 ///< time bins used by the yaw fit
  double yaw_excitation = 0.0;      ///< RMS forward specific force about its chunk means [m/s^2]
  double yaw_residual_rms = 0.0;    ///< RMS residual of the yaw fit per bin [m/s^2]
  Vec3 mounting_rpy = Vec3::Zero();  ///< with the corrections applied [rad]
  Vec3 manifest_mounting_rpy = Vec3::Zero();
};

/// The Body-IMU's mounting roll and pitch from its own data (docs/filter.md section 15):
/// the vehicle's z-axis is the axis it turns about. On any ground a vehicle yaws about its
/// own z, so the principal axis of the rates' scatter while turning is v z in the b-frame
/// (the terrain's pitch and roll rates are smaller and uncorrelated with the yaw rate).
/// It also keeps the data in time bins for the yaw (estimate_body_yaw()).
class BodyImuCalibrator {
 public:
  /// `expected_end`: as WheelImuCalibrator's (the bin series is reserved up to it).
  BodyImuCalibrator(const ImuModule& module, double static_start, double static_end,
                    const InstallationCalibrationOptions& opt = {}, double expected_end = 0.0);
  void add(const ImuSample& sensor_sample);
  /// Roll and pitch; the yaw is the manifest's until estimate_body_yaw() sets it.
  BodyImuCalibration result() const;
  const ImuModule& module() const { return module_; }
  const BinSeries<BodyBin>& bins() const { return bins_; }

 private:
  void close_chunk();
  ImuModule module_;
  InstallationCalibrationOptions opt_;
  Mat3 C_BtoV_;
  StaticPeriodSums static_;
  double chunk_start_ = -1.0, t_ = 0.0;
  // Turning: the rate scatter, whole run and current chunk; the per-chunk axes.
  Mat3 turn_all_ = Mat3::Zero(), turn_chunk_ = Mat3::Zero();
  double turn_time_ = 0.0, turn_chunk_time_ = 0.0, yaw_sum_ = 0.0;
  Vec3 axis_sum_ = Vec3::Zero(), axis_sq_ = Vec3::Zero();
  int axis_chunks_ = 0;
  BinSeries<BodyBin> bins_;
};

/// The Body-IMU's mounting yaw (docs/filter.md section 15), from the specific force (gravity
/// included) that it shares with the wheels' axles, not from the NHC (see there): a
/// Wheel-IMU's accelerometer along its axle (v y) reads the vehicle's lateral specific force
/// (the lateral acceleration and the ground's bank), which is the Body-IMU's too but for the
/// rotational terms of their offset. A yaw error delta adds delta times the forward specific
/// force (the acceleration and the ground's grade) to the Body-IMU's lateral one:
///   f_y(body) - f_axle(wheels) = delta f_x(body) + psi'' dp_x - psi'^2 dp_y + b,
/// dp the Body-IMU's position relative to the wheels' mean, b the accelerometer biases,
/// eliminated per chunk of `chunk_s`. Fitted over time bins of `yaw_bin_s` for delta and
/// the correction of dp from the manifest's. No wheel speed enters (slip does not bias it).
/// `wheel_results`: the Wheel-IMUs' estimates (their axles), in the order of `wheels`.
/// Sets the yaw, the position corrections and `mounting_rpy` of `body_result`; without a
/// Wheel-IMU, or with too little acceleration, the manifest's yaw is kept (not observed).
void estimate_body_yaw(const BodyImuCalibrator& body, const std::vector<const WheelImuCalibrator*>& wheels,
                       const std::vector<WheelImuCalibration>& wheel_results,
                       const InstallationCalibrationOptions& opt, BodyImuCalibration& body_result);

/// The relative radius of two sides' Wheel-IMUs from their rate series (module y in the
/// v-frame tells the sides; more than one module on a side, e.g. several chips on one
/// wheel, are averaged). Sets `wheel_radius` in each of `results` (same order as
/// `cals`); a single side leaves every radius at the manifest's, not observed.
void estimate_relative_radius(const std::vector<const WheelImuCalibrator*>& cals,
                              const InstallationCalibrationOptions& opt,
                              std::vector<WheelImuCalibration>& results);

}  // namespace wheelins
