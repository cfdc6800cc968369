// The installation calibration's per-sample sums (docs/filter.md section 15): the static
// period's (the gyro bias, gravity), the time-bin series the relative radius and a Body-IMU's
// yaw are fitted over (BinSeries of RateBin, AxleBin, BodyBin), and the helpers that index
// and reserve them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

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

/// Sums over one time bin of a Body-IMU's data (the bins of AxleBin), in the v-frame given
/// by the manifest mounting.
struct BodyBin {
  double dt = 0.0;       ///< sampled time in the bin [s]
  Vec3 w = Vec3::Zero(); ///< integral of the rate, static-period bias removed [rad]
  Vec3 f = Vec3::Zero(); ///< integral of the specific force [m/s]
};

namespace calib_detail {

/// A sample interval longer than this is a gap in the data (a dropout, a removed stretch).
inline constexpr double kMaxGap = 0.1;

/// The index of the rate-series bin a sample falls in (bins of `bin_s` from the static
/// period's end, by the sample's mid-time); -1 before the first bin or without bins.
inline std::ptrdiff_t rate_bin_index(const ImuSample& s, double static_end, double bin_s) {
  if (!(bin_s > 0.0)) return -1;
  const double k = std::floor((s.t - 0.5 * s.dt - static_end) / bin_s);
  return k >= 0.0 && k < 1e8 ? static_cast<std::ptrdiff_t>(k) : -1;
}

/// Room for the bins up to `expected_end`, at most 2^18 of them (a hint: the series grows
/// with the data; a time span alone never sizes memory).
template <class Bin>
void reserve_bins(BinSeries<Bin>& bins, double static_end, double expected_end, double bin_s) {
  const double span = expected_end - static_end;
  if (std::isfinite(span) && span > 0.0 && bin_s > 0.0)
    bins.reserve(static_cast<std::size_t>(std::min(span / bin_s, 262144.0)) + 2);
}

}  // namespace calib_detail

}  // namespace wheelins
