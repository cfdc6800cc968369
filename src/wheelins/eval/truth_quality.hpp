// Quality checks of a reference trajectory: the gaps, jumps and repeated fixes a GNSS
// track (or any truth) may hold, found record by record so that the streaming evaluation
// can leave the bad epochs out as it goes (metrics.hpp) and report them.
//
// Definitions (positions in a local NED frame, horizontal = north/east):
//  * Interval: the time between consecutive records. The median interval is taken over the
//    (up to) kMedianWindow intervals before the one judged, so a truth whose rate changes
//    part-way is judged by its current rate.
//  * Gap: an interval longer than gap_factor (5) times that median. The first interval is
//    never a gap (there is nothing to compare it with). A gap holds no truth epochs, so
//    nothing is scored inside it; what it affects is what is computed across it: the
//    course (metrics.hpp) is not, and the distance counts the straight line across it (a
//    lower bound of the path driven; reported as gap_distance).
//  * Repeated fix: a record whose lat/lon/h equal the previous record's exactly: a receiver
//    repeating its last fix, or a vehicle standing still. Where the truth has a velocity
//    (the 11-column layout) and it is below kStandingSpeed the vehicle stands: not counted.
//    Otherwise counted, and a run of them lasting longer than a gap would is listed as a
//    stall. Speeds and accelerations are taken between distinct fixes, each at the time of
//    its first record, so a repeated fix does not read as a stop followed by a leap.
//  * Jump: a distinct fix reached from the last good fix at a horizontal speed above
//    max_speed (70 m/s), or with an acceleration above max_accel (3 g): the change between
//    the velocity over the last good interval and the velocity to the new fix, divided by
//    half the time spanned by the two intervals. The acceleration is judged only where both
//    intervals are at least min_accel_interval (0.05 s) long and the earlier one is not a
//    gap (over a few milliseconds millimetres of position noise are a large acceleration:
//    denser truth is checked by its speed only). A jumped fix, and its repeats, are bad:
//    left out of the evaluation. The next fix is judged against the last good one; if it
//    fails there but is plausible from the jumped fix, the track has stepped: it is taken
//    as good from then on (the step itself stays a jump and is not counted as distance).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <string>
#include <vector>

#include "wheelins/io/truth.hpp"

namespace wheelins::eval {

/// The thresholds of the checks (the definitions above).
struct TruthQualityOptions {
  double gap_factor = 5.0;               ///< a gap: an interval > gap_factor x the median
  double max_speed = 70.0;               ///< [m/s] horizontal speed between fixes
  double max_accel = 3.0 * 9.80665;      ///< [m/s^2] horizontal acceleration over neighbouring fixes
  double min_accel_interval = 0.05;      ///< [s] shorter intervals are not used for the acceleration
};

/// [m/s] below this truth speed a repeated position is a vehicle standing still.
constexpr double kStandingSpeed = 0.1;
/// Intervals the median of the gap test is taken over.
constexpr std::size_t kMedianWindow = 100;
/// Gaps, stalls and jumps listed in a report (all are counted).
constexpr std::size_t kMaxListedTruthEvents = 50;

/// A gap (or, with repeated > 0, a stall: the same fix repeated across it).
struct TruthGap {
  double t_from = 0.0, t_to = 0.0;  ///< [s] the records before and after it
  std::uint64_t record = 0;         ///< 0-based index of the record after it
  std::uint64_t repeated = 0;       ///< repeated records inside a stall
};

/// A jump in the truth.
struct TruthJump {
  double t = 0.0;             ///< [s] the jumped fix
  std::uint64_t record = 0;   ///< its 0-based index
  double speed = 0.0;         ///< [m/s] from the last good fix
  double accel = 0.0;         ///< [m/s^2]; NaN where it was not judged
};

struct TruthQualityReport {
  std::uint64_t records = 0;
  std::uint64_t repeated = 0;          ///< records repeating the previous record's position
  std::uint64_t gap_count = 0;         ///< gaps, stalls not included
  std::uint64_t stall_count = 0;
  std::uint64_t jump_count = 0;
  std::uint64_t bad_records = 0;       ///< jumped fixes and their repeats
  double gap_seconds = 0.0;            ///< total time inside gaps and stalls
  double gap_distance = 0.0;           ///< [m] the straight lines across gaps and stalls
  double median_interval = 0.0;        ///< [s] over the last kMedianWindow intervals; NaN with one record
  std::vector<TruthGap> gaps;          ///< gaps and stalls in time order, the first kMaxListedTruthEvents
  std::vector<TruthJump> jumps;        ///< the first kMaxListedTruthEvents
  bool clean() const { return gap_count == 0 && stall_count == 0 && jump_count == 0; }
};

/// The checks fed record by record (time order). Memory: kMedianWindow intervals, a few fixes
/// and the listed events.
class TruthQualityMonitor {
 public:
  /// What one record is.
  struct Verdict {
    bool repeated = false;  ///< same position as the previous record
    bool bad = false;       ///< a jumped fix or a repeat of one: leave it out
    bool jump = false;      ///< the jumped fix itself (a new jump)
    bool gap_before = false;  ///< the interval before it is a gap (or a stall ends here)
    bool stepped = false;   ///< a good fix taken after a jump from the jumped fix (a step)
    double step = 0.0;      ///< [m] horizontal distance from the fix it is judged from (0 if bad)
  };
  /// Throws InputError for thresholds out of range.
  explicit TruthQualityMonitor(const TruthQualityOptions& options = {});
  /// The verdict on the next record: time [s], position in a local NED frame [m] and the
  /// truth's own horizontal speed [m/s] (NaN when it has no velocity).
  Verdict add(double t, const Vec3& p_ned, double speed);
  const TruthQualityReport& report() const { return report_; }

 private:
  struct Fix {
    double t = 0.0;
    Vec3 p = Vec3::Zero();
  };
  double median() const;

  TruthQualityOptions opt_;
  TruthQualityReport report_;
  std::deque<double> window_;
  double median_cache_ = std::numeric_limits<double>::quiet_NaN();
  bool have_prev_ = false;
  Fix prev_;                    // the previous record
  bool prev_bad_ = false;       // it was bad
  Fix run_start_;               // the first record of the current run of one position
  bool run_moving_ = false;     // not standing still at its start (or not known)
  std::uint64_t run_repeats_ = 0;
  bool have_good_ = false, have_ref_ = false, have_flagged_ = false;
  Fix good_, before_good_, flagged_;
  bool ref_gap_ = false;        // the interval before_good_ -> good_ is a gap
};

/// The checks over a whole truth (positions in the local frame at its first record).
TruthQualityReport check_truth_quality(const TruthData& truth, const TruthQualityOptions& options = {});

/// A few lines for people: the counts and the listed events (at most `max_lines` of them).
std::string describe_truth_quality(const TruthQualityReport& report, std::size_t max_lines = 10);

}  // namespace wheelins::eval
