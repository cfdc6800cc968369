// The truth quality checks of truth_quality.hpp: gaps against the running median interval,
// repeated fixes and stalls, jumps by speed and acceleration between distinct fixes.
#include "wheelins/eval/truth_quality.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "wheelins/nav/types.hpp"

namespace wheelins::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double horizontal(const Vec3& d) { return d.head<2>().norm(); }

}  // namespace

TruthQualityMonitor::TruthQualityMonitor(const TruthQualityOptions& o) : opt_(o) {
  if (!(o.gap_factor > 1.0 && o.gap_factor <= 1e6))
    throw InputError("truth gap factor must be in (1, 1e6], got " + std::to_string(o.gap_factor));
  if (!(o.max_speed > 0.0 && std::isfinite(o.max_speed)))
    throw InputError("truth jump speed must be a positive number, got " + std::to_string(o.max_speed));
  if (!(o.max_accel > 0.0 && std::isfinite(o.max_accel)))
    throw InputError("truth jump acceleration must be a positive number, got " + std::to_string(o.max_accel));
  if (!(o.min_accel_interval >= 0.0 && std::isfinite(o.min_accel_interval)))
    throw InputError("the shortest interval of the acceleration test must be >= 0, got " +
                     std::to_string(o.min_accel_interval));
  report_.median_interval = kNaN;
}

double TruthQualityMonitor::median() const {
  if (window_.empty()) return kNaN;
  std::array<double, kMedianWindow> v{};
  std::copy(window_.begin(), window_.end(), v.begin());
  const auto n = static_cast<std::ptrdiff_t>(window_.size());
  std::nth_element(v.begin(), v.begin() + n / 2, v.begin() + n);
  return v[static_cast<std::size_t>(n / 2)];
}

TruthQualityMonitor::Verdict TruthQualityMonitor::add(double t, const Vec3& p, double speed) {
  Verdict v;
  const std::uint64_t record = report_.records++;
  const bool moving = !(speed < kStandingSpeed);  // NaN (no truth velocity): not known to stand
  if (!have_prev_) {
    have_prev_ = have_good_ = true;
    prev_ = run_start_ = good_ = Fix{t, p};
    run_moving_ = moving;
    return v;
  }
  const double dt = t - prev_.t;
  // The running median, taken again every 16 records once the window is full (a copy and a
  // selection of 100 intervals per record cost more than the rest of an evaluation).
  if (window_.size() < kMedianWindow || record % 16 == 0 || !std::isfinite(median_cache_)) median_cache_ = median();
  const double med = median_cache_;
  const bool gap = !window_.empty() && dt > opt_.gap_factor * med;
  window_.push_back(dt);
  if (window_.size() > kMedianWindow) window_.pop_front();
  report_.median_interval = med;

  auto list_gap = [&](double from, double to, std::uint64_t repeats) {
    if (repeats > 0) ++report_.stall_count;
    else ++report_.gap_count;
    report_.gap_seconds += to - from;
    if (report_.gaps.size() < kMaxListedTruthEvents) report_.gaps.push_back({from, to, record, repeats});
  };

  if (p == prev_.p) {  // a repeated position
    v.repeated = true;
    if (moving) ++report_.repeated;
    ++run_repeats_;
    v.bad = prev_bad_;
    if (v.bad) ++report_.bad_records;
    // A gap while standing still is a gap; a moving run's is judged as a stall at its end.
    if (gap && !run_moving_) {
      list_gap(prev_.t, t, 0);
      v.gap_before = true;
    }
    prev_ = Fix{t, p};
    return v;
  }

  // A distinct fix closes the run of the previous position.
  if (run_repeats_ > 0 && run_moving_ && !std::isnan(med) && t - run_start_.t > opt_.gap_factor * med) {
    list_gap(run_start_.t, t, run_repeats_);
    v.gap_before = true;
  } else if (gap) {
    list_gap(prev_.t, t, 0);
    v.gap_before = true;
  }
  run_start_ = Fix{t, p};
  run_moving_ = moving;
  run_repeats_ = 0;
  prev_ = Fix{t, p};

  // Jump: speed (and acceleration) from the last good fix.
  const double dt_new = t - good_.t;
  const double spd = horizontal(p - good_.p) / dt_new;
  double acc = kNaN;
  bool ok = spd <= opt_.max_speed;
  const double dt_ref = good_.t - before_good_.t;
  if (have_ref_ && !ref_gap_ && !v.gap_before && dt_new >= opt_.min_accel_interval &&
      dt_ref >= opt_.min_accel_interval) {
    const Eigen::Vector2d v_ref = (good_.p - before_good_.p).head<2>() / dt_ref;
    const Eigen::Vector2d v_new = (p - good_.p).head<2>() / dt_new;
    acc = (v_new - v_ref).norm() / (0.5 * (t - before_good_.t));
    ok = ok && acc <= opt_.max_accel;
  }
  Fix anchor = good_;
  if (!ok && have_flagged_ && horizontal(p - flagged_.p) / (t - flagged_.t) <= opt_.max_speed) {
    anchor = flagged_;  // the track stepped at the jumped fix: follow it from there
    ok = true;
    v.stepped = true;
  }
  if (!ok) {
    v.bad = v.jump = true;
    ++report_.jump_count;
    ++report_.bad_records;
    if (report_.jumps.size() < kMaxListedTruthEvents) report_.jumps.push_back({t, record, spd, acc});
    flagged_ = Fix{t, p};
    have_flagged_ = true;
    prev_bad_ = true;
    return v;
  }
  v.step = horizontal(p - anchor.p);
  if (v.gap_before) report_.gap_distance += v.step;
  before_good_ = anchor;
  good_ = Fix{t, p};
  have_ref_ = true;
  ref_gap_ = v.gap_before;
  have_flagged_ = false;
  prev_bad_ = false;
  return v;
}

TruthQualityReport check_truth_quality(const TruthData& truth, const TruthQualityOptions& options) {
  TruthQualityMonitor m(options);
  if (truth.records.empty()) return m.report();
  const earth::LocalFrame frame(truth.records.front().lla);
  for (const TruthRecord& r : truth.records)
    m.add(r.t, frame.ned_from_geodetic(r.lla),
          truth.has_velocity ? r.v_ned.head<2>().norm() : std::numeric_limits<double>::quiet_NaN());
  return m.report();
}

std::string describe_truth_quality(const TruthQualityReport& r, std::size_t max_lines) {
  char buf[256];
  std::string o;
  if (r.clean() && r.repeated == 0) {
    std::snprintf(buf, sizeof buf, "no gaps, jumps or repeated fixes (%llu records, median interval %.3g s)\n",
                  static_cast<unsigned long long>(r.records), r.median_interval);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "%llu gaps and %llu stalls (%.1f s, %.1f m straight across), %llu jumps (%llu records left "
                "out), %llu repeated fixes; %llu records, median interval %.3g s\n",
                static_cast<unsigned long long>(r.gap_count), static_cast<unsigned long long>(r.stall_count),
                r.gap_seconds, r.gap_distance, static_cast<unsigned long long>(r.jump_count),
                static_cast<unsigned long long>(r.bad_records), static_cast<unsigned long long>(r.repeated),
                static_cast<unsigned long long>(r.records), r.median_interval);
  o += buf;
  // Gaps and jumps merged in time order.
  std::size_t g = 0, j = 0, lines = 0;
  while ((g < r.gaps.size() || j < r.jumps.size()) && lines < max_lines) {
    if (j >= r.jumps.size() || (g < r.gaps.size() && r.gaps[g].t_from <= r.jumps[j].t)) {
      const TruthGap& x = r.gaps[g++];
      if (x.repeated)
        std::snprintf(buf, sizeof buf, "  stall %.3f .. %.3f s (%.2f s, the fix repeated %llu times)\n", x.t_from,
                      x.t_to, x.t_to - x.t_from, static_cast<unsigned long long>(x.repeated));
      else
        std::snprintf(buf, sizeof buf, "  gap   %.3f .. %.3f s (%.2f s)\n", x.t_from, x.t_to, x.t_to - x.t_from);
    } else {
      const TruthJump& x = r.jumps[j++];
      if (std::isfinite(x.accel))
        std::snprintf(buf, sizeof buf, "  jump  at %.3f s (record %llu): %.1f m/s, %.1f m/s^2 from the last good fix\n",
                      x.t, static_cast<unsigned long long>(x.record), x.speed, x.accel);
      else
        std::snprintf(buf, sizeof buf, "  jump  at %.3f s (record %llu): %.1f m/s from the last good fix\n", x.t,
                      static_cast<unsigned long long>(x.record), x.speed);
    }
    o += buf;
    ++lines;
  }
  const std::uint64_t listed_total = r.gap_count + r.stall_count + r.jump_count;
  if (listed_total > lines)
    o += "  ... and " + std::to_string(listed_total - lines) + " more\n";
  return o;
}

}  // namespace wheelins::eval
