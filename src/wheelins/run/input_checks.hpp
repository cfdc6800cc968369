// The checks a module's samples pass on their way into the navigator of a run; the
// run driver applies them to the file readers (run/run.cpp), the Python module's
// streaming navigator to the samples pushed to it, so both navigate the same samples.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <memory>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

/// One module's samples as they enter the navigator, with the checks a navigation user
/// expects of them (docs/faults.md, "Input checks"):
///  * a sample beyond the sensor range (the manifest's gyro_range_dps / accel_range_m_s2,
///    else kDefaultGyroLimit / kDefaultAccelLimit) is a fault: left out, its interval given
///    to the next sample (isolate and continue), or an error without fault handling;
///  * the records' real rate (median interval of the first ones) matches rate_hz;
///  * in the static period, the data are increments or rates as declared (the specific force
///    read both ways), the IMU does not turn, and the specific force is gravity.
/// A failed check is an InputError naming the source (the quoted file) and the figure.
class InputChecks {
 public:
  /// `source` names the samples in messages (the quoted file name for a file).
  InputChecks(const ModuleSpec& spec, const Manifest& m, bool isolate, const WarningSink& warn,
              std::string source);
  /// Checks sample `index` (0-based, of its source) and adjusts it (the interval of samples
  /// left out before it); false: the sample is left out (beyond the range).
  bool admit(ImuSample& s, std::uint64_t index);
  /// The checks still open at the end of the data.
  void finish();
  std::uint64_t dropped() const { return dropped_; }

 public:
  static constexpr double kDefaultGyroLimit = 20000.0 * kDeg;  ///< [rad/s] no range declared
  static constexpr double kDefaultAccelLimit = 2000.0;         ///< [m/s^2] about 200 g
  static constexpr double kStaticMaxRate = 5.0 * kDeg;         ///< mean rate at rest [rad/s]
  static constexpr double kGravityTolerance = 0.05;            ///< |f| at rest vs gravity

 private:
  void check_rate(const ImuSample& s);
  void finish_rate_check();
  std::string period() const;
  void check_format();
  void check_static();
  void out_of_range(const ImuSample& s, bool gyro, std::uint64_t index);

  std::string source_;
  const ModuleSpec& spec_;
  bool isolate_;
  WarningSink warn_;
  double gyro_limit_ = 0.0, accel_limit_ = 0.0;
  double carry_ = 0.0, first_drop_t_ = -1.0;
  std::uint64_t dropped_ = 0;
  std::uint64_t n_intervals_ = 0;
  std::vector<double> intervals_;
  bool rate_checked_ = false;
  double static_start_, static_end_, gravity_;
  bool gravity_given_;
  bool static_checked_ = false;
  bool format_checked_ = false;
  double fmt_sum_ = 0.0, fmt_time_ = 0.0;
  std::uint64_t fmt_n_ = 0, warned_ = 0;
  Vec3 sum_dtheta_ = Vec3::Zero(), sum_dvel_ = Vec3::Zero();
  double static_time_ = 0.0;
  std::uint64_t static_n_ = 0;
};

/// One module's file through the input checks: what a run (and its calibration pass) reads.
class CheckedStream final : public ImuStream {
 public:
  CheckedStream(std::unique_ptr<ImuFileReader> reader, const ModuleSpec& spec, const Manifest& m,
                bool isolate, const WarningSink& warn);

  bool next(ImuSample& s) override {
    while (reader_->next(s))
      if (checks_.admit(s, reader_->index())) return true;
    checks_.finish();
    return false;
  }

  std::uint64_t dropped() const { return checks_.dropped(); }
  const ImuFileReader& reader() const { return *reader_; }

 private:
  std::unique_ptr<ImuFileReader> reader_;
  InputChecks checks_;
};

}  // namespace wheelins
