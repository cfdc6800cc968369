// A Wheel-IMU's axle direction in its frame (the mounting pitch and yaw) and its lever arm to
// the wheel centre, from whole-turn averages of its own data (docs/filter.md section 15);
// it also keeps the time-bin series of the relative radius (calib/relative_radius.hpp) and
// of a Body-IMU's yaw (calib/body_imu_calibrator.hpp).
#pragma once

#include "wheelins/calib/bins.hpp"
#include "wheelins/calib/calibration_types.hpp"
#include "wheelins/math/rotation.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/nav/vehicle.hpp"

namespace wheelins {

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
  /// Centred (within-chunk) sums over chunks: each chunk's regressors taken about its own
  /// means, which eliminates the accelerometer bias of the chunk.
  struct CentredSums {
    double cc = 0.0, ss = 0.0, chunks = 0.0, rows = 0.0;
    Vec3 cm = Vec3::Zero(), sm = Vec3::Zero();
    Mat3 mm = Mat3::Zero();
    /// Chunk k's sums, if it has two turns or more.
    void add(const RegressionSums& k) {
      if (k.n < 2.0) return;
      cc += k.cc - k.c * k.c / k.n;
      ss += k.ss - k.s * k.s / k.n;
      cm += k.cm - k.c * k.m / k.n;
      sm += k.sm - k.s * k.m / k.n;
      mm += k.mm - k.m * k.m.transpose() / k.n;
      chunks += 1.0;
      rows += 2.0 * k.n;
    }
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
  CentredSums closed_;  ///< over all closed chunks
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

}  // namespace wheelins
