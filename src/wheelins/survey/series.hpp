// One IMU module's samples as an evenly spaced series of mean rates: what the data
// surveys (survey/traits.hpp, survey/clock.hpp) work on. Memory is bounded: at most
// `max_span` seconds of data and `max_samples` records are kept, whatever the file holds
// (the rest is only read through for the time of its last record), so a file with times in
// the wrong unit (milliseconds read as seconds) costs a bounded series, never an unbounded
// allocation.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::survey {

struct SeriesOptions {
  double bin = 0.01;            ///< [s] the series' step
  double max_span = 1800.0;     ///< [s] of data read from the first record
  double skip_before = -1e300;  ///< records before this time (offset applied) are skipped
  std::uint64_t max_samples = 20'000'000;
  /// Samples beyond these (any axis) cannot come from the sensor and are left out, as the
  /// run's input checks leave them out (run/input_checks.hpp).
  double gyro_limit = 20000.0 * kDeg;  ///< [rad/s]
  double accel_limit = 2000.0;         ///< [m/s^2]
};

/// Mean gyro rate and specific force per bin; bins without a sample hold the linear
/// interpolation of their neighbours and are marked in `filled` (0).
struct Series {
  std::string module;
  std::filesystem::path file;
  double t0 = 0.0;   ///< start of bin 0 (module time, offset applied) [s]
  double dt = 0.01;  ///< bin length [s]
  std::vector<Vec3> gyro;   ///< [rad/s]
  std::vector<Vec3> accel;  ///< [m/s^2]
  std::vector<std::uint8_t> filled;
  double t_first = 0.0, t_last = 0.0;  ///< first and last record in the series [s]
  double t_end = 0.0;                  ///< the file's last record [s] (beyond the series when truncated)
  std::uint64_t samples = 0;           ///< records read
  std::uint64_t left_out = 0;          ///< records beyond the sensor's range
  bool truncated = false;              ///< the file goes on beyond what was read

  std::size_t size() const { return gyro.size(); }
  /// Middle of bin i [s].
  double time(std::size_t i) const { return t0 + (static_cast<double>(i) + 0.5) * dt; }
  /// The bin holding time t, clamped to the series.
  std::size_t index(double t) const;
};

/// Reads a module's file into a Series (InputError from the reader names the file).
Series read_series(const std::string& module, const std::filesystem::path& file,
                   const ImuReadOptions& read, const SeriesOptions& options = {});

/// Linear interpolation of a per-bin signal of `s` at time t (clamped at the ends).
double sample_at(const Series& s, const std::vector<double>& signal, double t);

/// Moving average over `n` bins (centred; shorter at the ends).
std::vector<double> moving_average(const std::vector<double>& x, int n);

}  // namespace wheelins::survey
