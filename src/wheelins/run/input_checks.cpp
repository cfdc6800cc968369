// The input checks of input_checks.hpp: sensor range (a sample left out gives its interval
// to the next), the real rate, the sample format and the static period.
#include "wheelins/run/input_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "wheelins/io/text_util.hpp"

namespace wheelins {
using io_detail::format_double;

namespace {
std::string fmt(double v, const char* f = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
}  // namespace

InputChecks::InputChecks(const ModuleSpec& spec, const Manifest& m, bool isolate,
                         const WarningSink& warn, std::string source)
    : source_(std::move(source)),
      spec_(spec),
      isolate_(isolate),
      warn_(warn),
      static_start_(m.static_start),
      static_end_(m.static_end),
      gravity_(m.gravity_or_default()),
      gravity_given_(m.gravity.has_value()) {
  gyro_limit_ = spec.gyro_range > 0.0 ? 1.05 * spec.gyro_range : kDefaultGyroLimit;
  accel_limit_ = spec.accel_range > 0.0 ? 1.05 * spec.accel_range : kDefaultAccelLimit;
}

bool InputChecks::admit(ImuSample& s, std::uint64_t index) {
  check_rate(s);
  // The format first (from the first static samples, before any is judged by range):
  // rates read as increments, or the reverse, are off by the rate in every figure.
  const bool finite = s.dtheta.allFinite() && s.dvel.allFinite();
  if (!format_checked_ && finite) {
    if (s.t >= static_start_ && s.t <= static_end_) {
      fmt_sum_ += s.dvel.norm();
      fmt_time_ += s.dt;
      if (++fmt_n_ >= 100) check_format();
    } else if (s.t > static_end_) {
      check_format();
    }
  }
  const double dt = s.dt;
  const double w = s.dtheta.cwiseAbs().maxCoeff() / dt, f = s.dvel.cwiseAbs().maxCoeff() / dt;
  // (maxCoeff may pass over a NaN: finiteness is checked on its own.)
  if (!finite || !(w <= gyro_limit_) || !(f <= accel_limit_)) {
    out_of_range(s, !s.dtheta.allFinite() || w > gyro_limit_, index);
    return false;
  }
  if (carry_ > 0.0) {  // the samples left out: their interval at this sample's rate
    const double k = (s.dt + carry_) / s.dt;
    s.dtheta *= k;
    s.dvel *= k;
    s.dt += carry_;
    carry_ = 0.0;
  }
  if (!static_checked_) {
    if (s.t >= static_start_ && s.t <= static_end_) {
      sum_dtheta_ += s.dtheta;
      sum_dvel_ += s.dvel;
      static_time_ += s.dt;
      ++static_n_;
    } else if (s.t > static_end_) {
      check_static();
    }
  }
  return true;
}

void InputChecks::finish() {
  if (!rate_checked_) finish_rate_check();
  if (!format_checked_) check_format();
  if (!static_checked_) check_static();
}

void InputChecks::out_of_range(const ImuSample& s, bool gyro, std::uint64_t index) {
  const double lim = gyro ? gyro_limit_ : accel_limit_;
  const Vec3 v = (gyro ? s.dtheta : s.dvel) / s.dt;
  const bool finite = s.dtheta.allFinite() && s.dvel.allFinite();
  std::string what = !finite ? std::string("a reading that is not finite (NaN or infinite)") :
                     std::string(gyro ? "gyro" : "accelerometer") + " reading " +
                     fmt(v.cwiseAbs().maxCoeff(), "%.4g") + (gyro ? " rad/s" : " m/s^2") +
                     " beyond the sensor range " + fmt(lim, "%.4g") + (gyro ? " rad/s" : " m/s^2") +
                     ((gyro ? spec_.gyro_range : spec_.accel_range) > 0.0
                          ? std::string(" (the manifest's range + 5 %)")
                          : std::string(" (no range in the manifest: the physical limit)"));
  const std::string where =
      source_ + ": record " + std::to_string(index) + " (0-based, t=" + format_double(s.t) + "): ";
  if (!isolate_)
    throw InputError(where + what + "; with fault handling on, such samples are left out");
  ++dropped_;
  carry_ += s.dt;
  if (first_drop_t_ < 0) first_drop_t_ = s.t;
  // Reported once the format is known to be right (else that error comes first).
  if (warn_ && format_checked_ && ++warned_ <= 5)
    warn_(where + what + ": sample left out (" + spec_.name + ")");
  else if (warn_ && format_checked_ && warned_ == 6)
    warn_(source_ + ": further samples beyond the range are left out and counted");
}

void InputChecks::check_rate(const ImuSample& s) {
  if (rate_checked_) return;
  if (n_intervals_++ == 0) return;  // the first sample's dt is the nominal one
  intervals_.push_back(s.dt);
  if (intervals_.size() >= 100) finish_rate_check();
}

void InputChecks::finish_rate_check() {
  rate_checked_ = true;
  if (intervals_.size() < 10) return;
  std::nth_element(intervals_.begin(), intervals_.begin() + intervals_.size() / 2,
                   intervals_.end());
  const double median = intervals_[intervals_.size() / 2];
  const double real = 1.0 / median;
  if (real < spec_.rate_hz / 1.25 || real > spec_.rate_hz * 1.25)
    throw InputError(source_ + ": the records are " + fmt(median, "%.4g") +
                     " s apart (median of the first " + std::to_string(intervals_.size()) +
                     " intervals), i.e. " + fmt(real, "%.4g") + " Hz, but the manifest declares " +
                     "rate_hz " + format_double(spec_.rate_hz) + " for module '" + spec_.name +
                     "'");
  intervals_.clear();
  intervals_.shrink_to_fit();
}

std::string InputChecks::period() const {
  char buf[96];
  std::snprintf(buf, sizeof buf, "the static period [%.3f, %.3f] s", static_start_, static_end_);
  return buf;
}

void InputChecks::check_format() {
  format_checked_ = true;
  if (fmt_n_ < 10 || !(fmt_time_ > 0.0)) return;  // too short to judge
  const std::string& file = source_;
  const std::string period = this->period();
  const double fmag = fmt_sum_ / fmt_time_;  // mean |f| read as declared [m/s^2]
  const bool rates = spec_.format == SampleFormat::kRate;
  const double other = rates ? fmag * spec_.rate_hz : fmag / spec_.rate_hz;  // read the other way
  const double g = gravity_;
  auto plausible = [&](double x) { return x > 0.5 * g && x < 2.0 * g; };
  if (!plausible(fmag)) {
    if (plausible(other))
      throw InputError(file + ": in " + period + " the accelerometer reads " + fmt(fmag, "%.4g") +
                       " m/s^2 taken as " + (rates ? "rates" : "increments") + ", " +
                       fmt(other, "%.4g") + " m/s^2 taken as " + (rates ? "increments" : "rates") +
                       " (gravity " + fmt(g, "%.4g") + "): the file holds " +
                       (rates ? "increments" : "rates") + ", the manifest says format: " +
                       to_string(spec_.format) + " (module '" + spec_.name + "')");
    throw InputError(file + ": in " + period + " the mean specific force is " + fmt(fmag, "%.4g") +
                     " m/s^2, far from gravity " + fmt(g, "%.4g") + " m/s^2 (module '" +
                     spec_.name +
                     "'): wrong units (g instead of m/s^2?), or not a 7-column IMU file");
  }
}

void InputChecks::check_static() {
  static_checked_ = true;
  if (static_n_ < 10 || !(static_time_ > 0.0)) return;  // too short to judge
  const std::string& file = source_;
  const std::string period = this->period();
  const double g = gravity_;
  const double turn = (sum_dtheta_ / static_time_).norm();
  if (turn > kStaticMaxRate)
    throw InputError(file + ": the IMU turns at " + fmt(turn / kDeg, "%.3g") +
                     " deg/s on average in " + period + " (module '" + spec_.name +
                     "'; at rest it reads the earth rate and "
                     "its bias, well under " +
                     fmt(kStaticMaxRate / kDeg, "%.3g") +
                     " deg/s): the vehicle moves there; move static_period_s to where it stands");
  const double fmean = (sum_dvel_ / static_time_).norm();
  if (std::abs(fmean - g) > kGravityTolerance * g)
    throw InputError(file + ": the mean specific force in " + period + " is " + fmt(fmean, "%.4g") +
                     " m/s^2, gravity " +
                     (gravity_given_ ? "(gravity_m_s2 of the manifest) " : "at the origin ") +
                     fmt(g, "%.4g") + " m/s^2, " + fmt(100.0 * std::abs(fmean - g) / g, "%.2g") +
                     " % apart (module '" + spec_.name +
                     "'): the vehicle accelerates or shakes "
                     "there, or gravity_m_s2 / the accelerometer scale is wrong");
}

CheckedStream::CheckedStream(std::unique_ptr<ImuFileReader> reader, const ModuleSpec& spec,
                             const Manifest& m, bool isolate, const WarningSink& warn)
    : reader_(std::move(reader)), checks_(spec, m, isolate, warn, io_detail::quote(reader_->file())) {}

}  // namespace wheelins
