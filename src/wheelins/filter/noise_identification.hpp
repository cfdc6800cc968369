// Noise identification from the data (docs/filter.md section 13).
//
// At rest: the Allan variance of each sensor's rate samples over the static period
// (IEEE Std 952-1997, annex C; El-Sheimy, Hou, Niu 2008), at octave cluster times
// tau = 2^L dt, accumulated sample by sample in O(levels) memory. The white-noise density
// (ARW for a gyro, VRW for an accelerometer) N^2 = sigma_A^2(tau) tau, the same at every
// tau on the white-noise line, is read at the shortest tau (up to 1 s) that no longer tau
// undercuts beyond its scatter (where a vibration has averaged out); the curve's minimum
// gives the bias instability B = min sigma_A / 0.664, or only a bound on it when the curve
// still falls as tau^-1/2 at the longest cluster time the period allows (a 30 s period
// cannot show a MEMS gyro's floor).
//
// In motion: the innovations of a velocity update, by Mehra's (1970) correlation
// method (VelocityNoiseMatcher): their variance alone cannot tell measurement noise
// from process noise at one update rate (covariance matching, Mohamed & Schwarz 1999),
// their lag-one correlation can. The velocity random walk enters every axis alike (H's
// velocity block is a rotation) and is taken from the constraint axes; the measurement
// noise is per axis (wheel speed, lateral and vertical constraint).
//
// The gyro bias instability in motion: its random walk from the corrections the
// updates make to the bias estimate (Mohamed & Schwarz's Q = K C K^T on the bias
// block), between a floor and the prior (BiasInstabilityMatcher).
//
// Everything here is fixed-size and allocation-free (it runs in the update path).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "wheelins/nav/types.hpp"

namespace wheelins {

/// Non-overlapping Allan variance of a 3-axis rate signal at cluster sizes 2^L samples.
class AllanAccumulator {
 public:
  static constexpr int kLevels = 14;  ///< clusters of 1 .. 8192 samples (41 s at 200 Hz)

  /// One rate sample (gyro [rad/s] or specific force [m/s^2]) over an interval dt.
  void add(const Vec3& y, double dt);
  void clear() { *this = AllanAccumulator(); }

  std::uint64_t samples() const { return samples_; }
  double mean_dt() const { return samples_ ? sum_dt_ / static_cast<double>(samples_) : 0.0; }
  /// Number of differences of consecutive cluster means at level L (clusters - 1).
  std::uint64_t differences(int level) const { return lv_[level].n_diff; }
  /// The cluster time of level L [s].
  double tau(int level) const { return mean_dt() * static_cast<double>(1u << level); }
  /// Allan variance per axis at level L (sigma_A^2 = E[(ybar_k+1 - ybar_k)^2] / 2).
  Vec3 variance(int level) const;

 private:
  struct Level {
    Vec3 sum = Vec3::Zero();       ///< of the cluster being filled
    std::uint32_t count = 0;       ///< samples in it
    Vec3 prev_mean = Vec3::Zero();
    bool has_prev = false;
    Vec3 sum_sq = Vec3::Zero();    ///< sum of squared differences of consecutive means
    std::uint64_t n_diff = 0;
  };
  void push(int level, const Vec3& cluster_mean);
  std::array<Level, kLevels> lv_{};
  std::uint64_t samples_ = 0;
  double sum_dt_ = 0.0;
};

/// What the Allan variance of one sensor shows.
struct SensorNoiseEstimate {
  bool valid = false;          ///< enough samples (>= 200)
  double white = 0.0;          ///< white-noise density, RMS over the axes [unit/sqrt(s)]
  Vec3 white_axes = Vec3::Zero();
  double white_tau = 0.0;      ///< the cluster time it was read at [s]
  /// Bias instability [unit]: min over tau of sigma_A / 0.664 (RMS over the axes) ...
  double bias_instability = 0.0;
  /// ... at this cluster time [s]; when the minimum lies at the longest usable tau the
  /// floor was not reached and bias_instability is an upper bound only.
  double bias_tau = 0.0;
  bool floor_reached = false;
  double duration = 0.0;       ///< [s]
};

/// The white noise is read at cluster times up to this [s] ...
inline constexpr double kWhiteTauMax = 1.0;
/// ... with at least this many differences.
inline constexpr std::uint64_t kWhiteMinDifferences = 20;

/// Reads an AllanAccumulator: the white noise N^2 = sigma_A^2(tau) tau at the shortest
/// cluster time (up to kWhiteTauMax, kWhiteMinDifferences differences) below which no longer
/// cluster time's sigma_A^2 tau falls by more than 3 of their scatters: the white-noise line
/// where a vibration has averaged out and before a bias instability rises; the bias
/// instability from the minimum of sigma_A over the levels with at least 8 differences.
SensorNoiseEstimate estimate_sensor_noise(const AllanAccumulator& a);

/// Noise identification from the innovations of one velocity measurement (3 axes: axis 0
/// the speed, 1-2 the constraints), by Mehra's (1970) correlation method: over an
/// exponentially weighted window, the innovations' variance C0 and lag-1 covariance C1 per
/// axis, with the filter's gain K = (H P H^T)_ii / S_ii, give for a random walk observed in
/// white noise
///     P = C1 + K C0,   R = (1 - K) C0 - C1,   Q = K (2 - K) P - K^2 R
/// (e_k+1 = (1 - K) e_k + w_k - K v_k, so C1 = (1 - K) P - K R and C0 = P + R): the
/// variance alone cannot tell the measurement noise from the process noise at one update
/// rate, its correlation can. The process noise enters every axis alike (H's velocity
/// block is a rotation), so the velocity random walk is taken from the constraint axes
/// (the speed axis also carries slip and radius errors); the measurement noise per axis.
class VelocityNoiseMatcher {
 public:
  struct Options {
    double window = 60.0;            ///< updates (e-folding length of the weights)
    double r_floor_fraction = 0.5;   ///< R never below this fraction (in sigma) of its nominal
    double vrw_max = 20.0 / 60.0;    ///< [m/s/sqrt(s)]
    double min_samples = 0.3;        ///< of the window before the estimates are used
  };
  /// Starts from the prior VRW (used until the window has filled), never going below
  /// vrw_floor (e.g. the white noise measured at rest), and the nominal R diagonal.
  void reset(const Options& opt, double vrw_prior, double vrw_floor, const Vec3& r_nominal);
  /// One accepted update: innovation dz, the diagonal of its predicted covariance S (made
  /// with the R and VRW in use now), and the interval since the previous update [s].
  void add(const Vec3& dz, const Vec3& S_diag, double dt);
  /// A gap in the sequence (an update skipped or rejected): the next one has no lag-1 pair.
  void break_sequence() { have_prev_ = false; }

  double vrw() const { return std::sqrt(q_); }  ///< [m/s/sqrt(s)]
  Vec3 r_diag() const { return r_; }            ///< [m^2/s^2]
  Vec3 r_nominal() const { return r0_; }
  bool adapted() const { return w1_ >= opt_.min_samples * opt_.window; }
  /// The mean normalized innovation squared per axis over the window (1 if consistent).
  Vec3 nis_axes() const;
  double weight() const { return w_; }

 private:
  Options opt_;
  double q_ = 0.0, q_floor_ = 0.0;
  Vec3 r_ = Vec3::Zero(), r0_ = Vec3::Zero();
  Vec3 c0_ = Vec3::Zero(), c1_ = Vec3::Zero(), k_ = Vec3::Zero(), s_ = Vec3::Zero();
  Vec3 prev_ = Vec3::Zero();
  bool have_prev_ = false;
  double w_ = 0.0, w1_ = 0.0, dt_ = 0.0;
};

/// The gyro bias instability in motion, from the corrections the updates make to the bias
/// estimate: q = E[|db|^2_max axis] / dt over a window, as the Gauss-Markov driving noise
/// 2 sigma^2 / tau, between sigma_floor and the prior sigma.
class BiasInstabilityMatcher {
 public:
  void reset(double window, double sigma_prior, double sigma_floor, double tau);
  void add(const Vec3& correction, double dt);
  double sigma() const { return sigma_; }
  double prior() const { return prior_; }

 private:
  double window_ = 60.0, prior_ = 0.0, floor_ = 0.0, tau_ = 3600.0, sigma_ = 0.0;
  double sum_ = 0.0, w_ = 0.0;
};

}  // namespace wheelins
