// The accuracy figures of metrics.hpp: the streaming Evaluator (truth interpolation,
// drift rate over distance segments, heading RMSE, NEES) and evaluate() on whole files.
#include "wheelins/eval/metrics.hpp"

#include "wheelins/io/text_util.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>
#include <stdexcept>

#include "wheelins/eval/aligned_evaluator.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTimeSlack = 1e-6;  // [s] end-point tolerance of the time brackets
constexpr double kCoincide = 1e-3;   // [s] a trajectory record "at" a truth epoch

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

double lerp(double a, double b, double f) { return a + (b - a) * f; }

std::string fixed(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

}  // namespace

std::vector<double> drift_rate_curve(const std::vector<double>& s, const std::vector<double>& err,
                                     double segment_length) {
  std::vector<double> curve;
  if (s.empty() || s.size() != err.size() || !(segment_length > 0.0)) return curve;
  if (!std::isfinite(s.back()) || s.back() / segment_length > 1e7)
    throw InputError("drift rate: " + std::to_string(s.back()) + " m in segments of " +
                     std::to_string(segment_length) + " m is more than 10^7 segments");
  // Tiny slack so that a distance of exactly k*l computed by summation still counts.
  const double slack = 1e-9 * std::max(1.0, s.back());
  const auto K = static_cast<std::size_t>(std::floor((s.back() + slack) / segment_length));
  curve.reserve(K);
  std::size_t i = 0;
  double running_max = 0.0;
  for (std::size_t k = 1; k <= K; ++k) {
    const double limit = static_cast<double>(k) * segment_length;
    while (i < s.size() && s[i] <= limit + slack) running_max = std::max(running_max, err[i++]);
    curve.push_back(running_max / limit);
  }
  return curve;
}

// ------------------------------------------------------------------ Evaluator

// The truth records go through three stages, each in time order, joined by their index:
//   1. on arrival: the quality verdict (truth_quality.hpp) and the path length;
//   2. matching: the trajectory interpolated to the record's time once two trajectory
//      samples bracket it (or it is known to lie outside / in a trajectory gap);
//   3. the course (only when the truth has no attitude): once a good fix course_baseline / 2
//      later has arrived (or a break, or the end).
// A record is scored when stages 2 and 3 are done; records leave in order, so the memory
// is the records within course_baseline / 2 plus those between two trajectory samples.
struct Evaluator::State {
  struct Sample {  // one trajectory record, positions in the evaluation frame (at the antenna)
    double t = 0.0;
    Vec3 p = Vec3::Zero();
    double heading = kNaN, sn = kNaN, se = kNaN;
    double yaw_rate = 0.0;   // [rad/s] over the interval ending here
    double lever_fwd = 0.0;  // [m] the antenna's forward offset, levelled (roll and pitch taken off)
  };
  enum class Match { kWaiting, kEpoch, kOutside, kGap, kSparse };
  struct Slot {  // one truth record on its way
    double t = 0.0, heading = kNaN, s = 0.0;
    double dt_truth = 0.0;  // to the previous truth record [s] (inf for the first)
    Vec3 p = Vec3::Zero();
    Mat3 R_local = Mat3::Identity();  // the evaluation frame's axes to the truth point's own NED
    bool bad = false;
    Match match = Match::kWaiting;
    Vec3 traj_p = Vec3::Zero();  // the interpolated trajectory
    double traj_heading = kNaN, sn = kNaN, se = kNaN, yaw_rate = 0.0, lever_fwd = 0.0;
    bool course_done = false;
    double course = kNaN, course_speed = kNaN;
  };
  struct CourseFix {  // a good distinct truth fix for the course
    double t = 0.0;
    Vec3 p = Vec3::Zero();
    std::uint64_t breaks = 0;  // breaks (gaps, steps) up to and including this fix
  };

  earth::LocalFrame frame;
  Sources src;
  EvalOptions opt;
  bool keep_series = false;
  bool use_course = false;
  EvalResult res;
  TruthQualityMonitor quality;

  Sample a, b;          // the last two trajectory samples (b the latest)
  std::size_t n_traj = 0;
  bool traj_ended = false;  // end_trajectory() was called
  double first_traj_t = 0.0;

  std::deque<Slot> slots;        // slots.front() has index `base`
  std::uint64_t base = 0;        // index of slots.front()
  std::uint64_t next_match = 0;  // the first slot still waiting for the trajectory
  std::uint64_t next_course = 0; // the first slot whose course is not done
  std::deque<CourseFix> course_fixes;
  std::uint64_t breaks = 0;      // breaks seen so far
  double last_break_t = -kInf;   // time of the last fix after a break

  bool have_truth = false;
  double truth_s = 0.0, first_truth_t = 0.0, last_truth_t = 0.0;
  // The truth's own local frame (at its first record) for its path length and quality
  // checks: the figures do not depend on the evaluation frame's origin.
  earth::LocalFrame truth_frame;
  double last_epoch_t = -kInf, covered_s = 0.0;  // coverage: time between scored epochs

  // Alignment, fixed at the first evaluated epoch.
  bool pivot_set = false;
  Vec3 pivot_traj = Vec3::Zero(), pivot_truth = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  double dpsi = 0.0;
  Eigen::Matrix2d R2 = Eigen::Matrix2d::Identity();

  double s0 = 0.0, sum_e2 = 0.0, sum_h2 = 0.0, max_h = 0.0, sum_nees = 0.0;
  std::size_t heading_count = 0, within = 0;
  EpochError last;

  // Drift curve (r_k = max{e_h : s <= k l} / (k l)), built as the epochs come.
  double running_max = 0.0;

  Mat3 C_frame_T;  // the evaluation frame's NED axes to ECEF

  State(const earth::LocalFrame& f, const Sources& s, const EvalOptions& o, bool keep)
      : frame(f), src(s), opt(o), keep_series(keep), quality(o.truth_quality),
        C_frame_T(earth::dcm_ecef_to_ned(f.origin().lat, f.origin().lon).transpose()) {
    use_course = !s.truth_has_attitude && s.traj_has_heading;
  }

  Slot& slot(std::uint64_t index) { return slots[static_cast<std::size_t>(index - base)]; }

  void drift_add(double dist, double err) {
    const double slack = 1e-9 * std::max(1.0, dist);
    for (;;) {
      const double limit = static_cast<double>(res.drift_curve.size() + 1) * opt.segment_length;
      if (dist <= limit + slack) break;
      res.drift_curve.push_back(running_max / limit);
    }
    running_max = std::max(running_max, err);
  }

  // The heading a slot's trajectory heading is compared with (NaN: none).
  double reference_heading(const Slot& x) const {
    if (!use_course) return x.heading;
    if (!std::isfinite(x.course)) return kNaN;
    // The antenna's course leads the heading by asin(yaw_rate * l_x / V) in a turn (l_x the
    // antenna's levelled forward offset, V its speed).
    const double lateral = x.yaw_rate * x.lever_fwd;
    if (lateral == 0.0) return x.course;
    if (!(std::abs(lateral) < x.course_speed)) return kNaN;
    return wrap_pi(x.course - std::asin(lateral / x.course_speed));
  }

  // A matched, good truth record scored against the trajectory.
  void epoch(const Slot& x) {
    Vec3 p = x.traj_p;
    double heading = x.traj_heading;
    const double ref = reference_heading(x);
    if (!pivot_set) {
      pivot_set = true;
      s0 = x.s;
      res.t_start = x.t;
      if (opt.align_origin) {
        res.aligned = true;
        res.align_method = "origin";
        pivot_traj = p;
        pivot_truth = x.p;
        res.align_offset = pivot_truth - pivot_traj;
        if (std::isfinite(heading) && std::isfinite(ref)) {
          dpsi = wrap_pi(ref - heading);
          res.align_rotated = true;
          res.align_yaw = dpsi;
          R = rot_z(dpsi);
          R2 = R.topLeftCorner<2, 2>();
        }
      }
    }
    if (opt.align_origin) {
      p = R * (p - pivot_traj) + pivot_truth;
      heading += dpsi;
    }
    EpochError e;
    e.t = x.t;
    e.distance = x.s - s0;
    // In the truth point's own north/east/down: exact whatever the evaluation frame's origin
    // (in a frame whose origin is far away, "horizontal" would mix in the height error).
    e.err_ned = x.R_local * (p - x.p);
    e.err_h = e.err_ned.head<2>().norm();
    e.heading_err = res.has_heading && std::isfinite(ref) ? wrap_pi(heading - ref) : kNaN;
    e.sigma_h = kNaN;
    e.nees_h = kNaN;
    if (res.has_sigma) {
      const double sn = x.sn, se = x.se;
      if (sn > 0.0 && se > 0.0 && std::isfinite(sn) && std::isfinite(se)) {
        const Eigen::Matrix2d P = R2 * Eigen::Vector2d(sn * sn, se * se).asDiagonal() * R2.transpose();
        const Eigen::Vector2d d = e.err_ned.head<2>();
        e.sigma_h = std::sqrt(P.trace());
        e.nees_h = d.dot(P.ldlt().solve(d));
        ++res.sigma_epochs;
        if (e.err_h <= 3.0 * e.sigma_h) ++within;
        sum_nees += e.nees_h;
      }
    }
    sum_e2 += e.err_h * e.err_h;
    res.max_error = std::max(res.max_error, e.err_h);
    if (std::isfinite(e.heading_err)) {
      sum_h2 += e.heading_err * e.heading_err;
      max_h = std::max(max_h, std::abs(e.heading_err));
      ++heading_count;
    }
    drift_add(e.distance, e.err_h);
    if (x.t - last_epoch_t <= opt.max_gap + kTimeSlack) covered_s += x.t - last_epoch_t;
    last_epoch_t = x.t;
    ++res.epochs;
    last = e;
    if (keep_series) res.series.push_back(e);
  }

  // Stage 2 of slot x: the trajectory between samples lo and hi at fraction f.
  void match(Slot& x, const Sample& lo, const Sample& hi, double f) {
    x.match = Match::kEpoch;
    x.traj_p = lo.p + (hi.p - lo.p) * f;
    if (src.traj_has_heading) x.traj_heading = lo.heading + wrap_pi(hi.heading - lo.heading) * f;
    if (res.has_sigma) {
      x.sn = lerp(lo.sn, hi.sn, f);
      x.se = lerp(lo.se, hi.se, f);
    }
    x.yaw_rate = hi.yaw_rate;
    x.lever_fwd = lerp(lo.lever_fwd, hi.lever_fwd, f);
  }

  // Matches the waiting truth records that the trajectory now brackets: those before the
  // latest sample b (bracket a..b), or all of them at the end (final).
  void drain(bool final) {
    while (next_match < base + slots.size()) {
      Slot& x = slot(next_match);
      if (n_traj == 0 || x.t < first_traj_t - kTimeSlack) {
        if (n_traj == 0 && !final) return;
        x.match = Match::kOutside;
      } else if (x.t < b.t) {
        // a.t <= x.t < b.t (or x before the first sample within the slack: its value).
        if (n_traj == 1 || x.t <= a.t) {
          match(x, n_traj == 1 ? b : a, n_traj == 1 ? b : a, 0.0);
        } else {
          const double span = b.t - a.t;
          if (span > opt.max_gap) {
            x.match = Match::kGap;
          } else if (span > std::max(kDenseInterval, 1.5 * x.dt_truth)) {
            // Records sparser than the truth: scored only where one falls on a truth epoch
            // (a line between records seconds apart is not the trajectory the tool computed).
            if (x.t - a.t <= kCoincide) match(x, a, a, 0.0);
            else if (b.t - x.t <= kCoincide) match(x, b, b, 0.0);
            else x.match = Match::kSparse;
          } else {
            match(x, a, b, std::clamp((x.t - a.t) / span, 0.0, 1.0));
          }
        }
      } else if (!final) {
        return;  // at or after the latest sample: wait for the next one
      } else if (x.t <= b.t + kTimeSlack) {
        match(x, b, b, 0.0);
      } else {
        x.match = Match::kOutside;
      }
      ++next_match;
    }
  }

  // Stage 3: the courses that the fixes seen so far decide (all of them at the end).
  void courses(bool final) {
    const double half = 0.5 * opt.course_baseline;
    while (next_course < base + slots.size()) {
      Slot& x = slot(next_course);
      if (!use_course || x.bad) {
        x.course_done = true;
        ++next_course;
        continue;
      }
      const bool ahead = !course_fixes.empty() && course_fixes.back().t >= x.t + half - kTimeSlack;
      if (!ahead && !final && !(last_break_t > x.t)) return;  // wait for later fixes
      x.course_done = true;
      ++next_course;
      // The fixes k (last at or before t - B/2) and j (first at or after t + B/2).
      auto j = std::lower_bound(course_fixes.begin(), course_fixes.end(), x.t + half - kTimeSlack,
                                [](const CourseFix& c, double t) { return c.t < t; });
      auto k = std::upper_bound(course_fixes.begin(), course_fixes.end(), x.t - half + kTimeSlack,
                                [](double t, const CourseFix& c) { return t < c.t; });
      if (j == course_fixes.end() || k == course_fixes.begin()) continue;
      --k;
      if (j->breaks != k->breaks) continue;  // a gap or a step between them
      const double dt = j->t - k->t;
      const Eigen::Vector2d d = (x.R_local * (j->p - k->p)).head<2>();  // in the local north/east
      const double speed = d.norm() / dt;
      if (!(dt > 0.0) || !(speed >= opt.course_min_speed)) continue;
      x.course = std::atan2(d.y(), d.x());
      x.course_speed = speed;
    }
  }

  // Scores (or counts) the slots whose stages are done, in order, and trims the course
  // fixes no slot needs any more.
  void score() {
    while (!slots.empty() && slots.front().match != Match::kWaiting && slots.front().course_done) {
      const Slot& x = slots.front();
      switch (x.match) {
        case Match::kOutside: ++res.skipped_outside; break;
        case Match::kGap: ++res.skipped_gap; break;
        case Match::kSparse: ++res.skipped_sparse; break;
        default:
          if (x.bad) ++res.skipped_truth_jump;
          else epoch(x);
      }
      slots.pop_front();
      ++base;
    }
    const double keep_from = (slots.empty() ? last_truth_t : slots.front().t) - 0.5 * opt.course_baseline;
    while (course_fixes.size() >= 2 && course_fixes[1].t <= keep_from - kTimeSlack) course_fixes.pop_front();
  }

  // The stages as far as the records seen allow: `traj_final` once no trajectory record
  // follows, `truth_final` once no truth record follows.
  void advance(bool traj_final, bool truth_final) {
    drain(traj_final);
    courses(truth_final);
    score();
  }
};

Evaluator::Evaluator(const earth::LocalFrame& frame, const Sources& sources,
                     const EvalOptions& opt, bool keep_series) {
  // Bounded work and memory: the drift curve has distance / l entries, so l has a floor.
  if (!(opt.segment_length >= kMinSegment && opt.segment_length <= kMaxSegment))
    throw InputError("segment length must be in [" + std::to_string(static_cast<int>(kMinSegment)) +
                     ", 1e6] m, got " + std::to_string(opt.segment_length));
  if (!(opt.max_gap > 0.0 && opt.max_gap <= 3600.0))
    throw InputError("maximum interpolation gap must be in (0, 3600] s, got " + std::to_string(opt.max_gap));
  if (!opt.antenna.allFinite() || opt.antenna.norm() > 100.0)
    throw InputError("the antenna lever arm must be finite and within 100 m of the reference point");
  if (!std::isfinite(opt.truth_time_offset))
    throw InputError("the truth time offset must be a finite number of seconds");
  if (!(opt.course_baseline > 0.0 && opt.course_baseline <= 60.0))
    throw InputError("the course baseline must be in (0, 60] s, got " + std::to_string(opt.course_baseline));
  if (!(opt.course_min_speed >= 0.0 && std::isfinite(opt.course_min_speed)))
    throw InputError("the course's minimum speed must be >= 0 m/s, got " + std::to_string(opt.course_min_speed));
  if (!opt.antenna.isZero() && !sources.traj_has_heading)
    throw InputError(quote(sources.traj_file) + ": the antenna lever arm needs the trajectory's heading, "
                     "which it does not have");
  s_ = std::make_unique<State>(frame, sources, opt, keep_series);
  EvalResult& r = s_->res;
  r.truth_file = sources.truth_file;
  r.traj_file = sources.traj_file;
  r.traj_format = sources.traj_format;
  r.truth_layout = sources.truth_layout;
  r.segment_length = opt.segment_length;
  r.max_gap = opt.max_gap;
  r.has_heading = (sources.truth_has_attitude || s_->use_course) && sources.traj_has_heading;
  r.heading_source = !sources.traj_has_heading ? "none" : sources.truth_has_attitude ? "truth" : "course";
  r.has_sigma = sources.traj_has_sigma;
  r.antenna = opt.antenna;
  r.truth_time_offset = opt.truth_time_offset;
}

Evaluator::~Evaluator() = default;

void Evaluator::end_trajectory() {
  s_->traj_ended = true;
  s_->advance(true, false);
}

std::size_t Evaluator::pending() const { return s_->slots.size(); }

void Evaluator::add_truth(const TruthRecord& r) {
  State& s = *s_;
  State::Slot x;
  x.t = r.t + s.opt.truth_time_offset;
  x.p = s.frame.ned_from_geodetic(r.lla);
  x.R_local = earth::dcm_ecef_to_ned(r.lla.lat, r.lla.lon) * s.C_frame_T;
  x.dt_truth = s.have_truth ? x.t - s.last_truth_t : kInf;  // the first: no interval known
  x.heading = s.src.truth_has_attitude ? r.rpy.z() : kNaN;
  const double speed = s.src.truth_has_velocity ? r.v_ned.head<2>().norm() : kNaN;
  if (!s.have_truth) s.truth_frame = earth::LocalFrame(r.lla);
  const TruthQualityMonitor::Verdict v = s.quality.add(x.t, s.truth_frame.ned_from_geodetic(r.lla), speed);
  x.bad = v.bad;
  // Path length over the good records (horizontal; a jump is no distance driven).
  if (s.have_truth) s.truth_s += v.step;
  else s.first_truth_t = x.t;
  x.s = s.truth_s;
  s.have_truth = true;
  s.last_truth_t = x.t;
  ++s.res.truth_records;
  if (s.n_traj >= 2 && x.t < s.a.t && x.t >= s.first_traj_t - kTimeSlack)
    throw std::logic_error("Evaluator: a truth record came after the trajectory had passed it");
  if (v.gap_before || v.stepped) {
    ++s.breaks;
    s.last_break_t = x.t;
  }
  if (s.use_course && !v.bad && !v.repeated) s.course_fixes.push_back({x.t, x.p, s.breaks});
  s.slots.push_back(x);
  s.advance(s.traj_ended, false);
}

void Evaluator::add_trajectory(const TrajectoryRecord& r) {
  State& s = *s_;
  if (s.traj_ended) throw std::logic_error("Evaluator: a trajectory record after end_trajectory()");
  if (!std::isfinite(r.t) || (s.n_traj > 0 && !(r.t > s.b.t)))
    throw InputError(quote(s.res.traj_file) + ": record " + std::to_string(s.n_traj) +
                     " (0-based): time " + std::to_string(r.t) +
                     (s.n_traj > 0 ? " is not after the previous record's " + std::to_string(s.b.t)
                                   : std::string(" is not a finite number")));
  // The same verdict as the trajectory file readers: a non-finite position is an error,
  // never an epoch compared as NaN (which every "max" and "within" test would pass).
  const bool pos_ok = s.src.traj_has_lla
                          ? std::isfinite(r.lla.lat) && std::isfinite(r.lla.lon) && std::isfinite(r.lla.h)
                          : r.p_inN.allFinite();
  const bool lever = !s.opt.antenna.isZero();
  const bool att_ok = !(s.src.traj_has_heading || lever) || std::isfinite(r.rpy.z());
  const bool rp_ok = !(lever && s.src.traj_has_roll_pitch) || (std::isfinite(r.rpy.x()) && std::isfinite(r.rpy.y()));
  if (!pos_ok || !att_ok || !rp_ok)
    throw InputError(quote(s.res.traj_file) + ": record " + std::to_string(s.n_traj) +
                     " (0-based, t=" + std::to_string(r.t) + "): " +
                     (!pos_ok ? "position" : !att_ok ? "heading" : "roll/pitch") + " is not finite");
  State::Sample k;
  k.t = r.t;
  k.p = s.src.traj_has_lla ? s.frame.ned_from_geodetic(r.lla) : r.p_inN;
  if (lever) {
    const Vec3 rpy = s.src.traj_has_roll_pitch ? r.rpy : Vec3(0.0, 0.0, r.rpy.z());
    k.p += dcm_from_euler(rpy) * s.opt.antenna;
    k.lever_fwd = (dcm_from_euler(Vec3(rpy.x(), rpy.y(), 0.0)) * s.opt.antenna).x();
  }
  if (s.src.traj_has_heading) {
    k.heading = r.rpy.z();
    if (s.n_traj > 0) k.yaw_rate = wrap_pi(k.heading - s.b.heading) / (k.t - s.b.t);
  }
  if (s.src.traj_has_sigma) {
    k.sn = r.p_std.x();
    k.se = r.p_std.y();
  }
  if (s.n_traj == 0) s.first_traj_t = r.t;
  s.a = s.n_traj ? s.b : k;
  s.b = k;
  ++s.n_traj;
  ++s.res.traj_records;
  s.advance(false, false);
}

EvalResult Evaluator::finish() {
  State& s = *s_;
  s.advance(true, true);
  EvalResult& res = s.res;
  res.truth_quality = s.quality.report();
  if (res.truth_records == 0) throw InputError(quote(res.truth_file) + ": no truth records");
  if (s.n_traj == 0) throw InputError(quote(res.traj_file) + ": no trajectory records");
  if (res.epochs == 0)
    throw InputError(quote(res.traj_file) + ": no truth epoch of " + quote(res.truth_file) +
                     " falls inside the trajectory (trajectory " + std::to_string(s.first_traj_t) +
                     " .. " + std::to_string(s.b.t) + " s, truth " +
                     std::to_string(s.first_truth_t) + " .. " + std::to_string(s.last_truth_t) +
                     " s" +
                     (res.skipped_gap ? ", or only inside gaps longer than the maximum gap" : "") +
                     (res.skipped_sparse ? ", or only between records sparser than the truth, none of them "
                                           "at a truth epoch" : "") +
                     (res.skipped_truth_jump ? ", or only at jumps of the truth" : "") +
                     "); do both use the same time scale (GPS seconds of week)?");
  res.t_end = s.last.t;
  res.duration = res.t_end - res.t_start;
  res.distance = s.last.distance;
  res.final_error = s.last.err_h;
  res.final_error_ratio = res.distance > 0.0 ? res.final_error / res.distance : kNaN;
  res.rms_error = std::sqrt(s.sum_e2 / static_cast<double>(res.epochs));
  // The segments completed by the total distance (same slack as drift_rate_curve()).
  const double slack = 1e-9 * std::max(1.0, res.distance);
  const auto K = static_cast<std::size_t>(std::floor((res.distance + slack) / res.segment_length));
  while (res.drift_curve.size() < K)
    res.drift_curve.push_back(s.running_max /
                              (static_cast<double>(res.drift_curve.size() + 1) * res.segment_length));
  res.drift_curve.resize(K);
  if (res.drift_curve.empty()) {
    res.drift_rate = kNaN;
  } else {
    double sum = 0.0;
    for (double r : res.drift_curve) sum += r;
    res.drift_rate = sum / static_cast<double>(res.drift_curve.size());
  }
  // Coverage: the time between scored epochs (no further apart than max_gap) over the
  // truth's span from the trajectory's start (a run navigates from the end of its static
  // period); below kMinCoverage the figures are not comparable with a full trajectory's.
  res.truth_span = s.last_truth_t - std::max(s.first_truth_t, s.first_traj_t);
  res.covered = s.covered_s;
  res.coverage = res.truth_span > 0.0 ? std::min(1.0, res.covered / res.truth_span) : 1.0;
  res.comparable = res.coverage >= kMinCoverage;
  res.heading_epochs = s.heading_count;
  if (s.heading_count > 0) {
    res.heading_rmse = std::sqrt(s.sum_h2 / static_cast<double>(s.heading_count));
    res.heading_max_abs = s.max_h;
  } else {
    res.has_heading = false;
    res.heading_rmse = res.heading_max_abs = kNaN;
  }
  if (res.sigma_epochs > 0) {
    res.within_3sigma = static_cast<double>(s.within) / static_cast<double>(res.sigma_epochs);
    res.mean_nees = s.sum_nees / static_cast<double>(res.sigma_epochs);
  } else {
    res.has_sigma = false;
    res.within_3sigma = res.mean_nees = kNaN;
  }
  return res;
}

namespace {

// One pass of evaluate(): every record through the (start-aligned) evaluator, each trajectory
// record first moved by `move` when given.
EvalResult evaluate_pass(const TruthData& truth, const TrajectoryData& traj, const earth::LocalFrame& frame,
                         const EvalOptions& opt, const RigidFit* move) {
  Evaluator::Sources src;
  src.truth_file = truth.file.string();
  src.traj_file = traj.file.string();
  src.traj_format = trajectory_format_name(traj.format);
  src.truth_layout = truth_layout_name(truth.layout);
  src.truth_has_attitude = truth.has_attitude;
  src.truth_has_velocity = truth.has_velocity;
  src.traj_has_lla = traj.has_lla;
  src.traj_has_heading = traj.has_heading;
  src.traj_has_roll_pitch = traj.has_roll_pitch;
  src.traj_has_sigma = traj.has_pos_std;
  StartAlignedEvaluator ev(frame, src, opt, true);
  if (truth.records.empty()) throw InputError(quote(truth.file) + ": no truth records");
  if (traj.records.empty()) throw InputError(quote(traj.file) + ": no trajectory records");
  // In step: the truth records before each trajectory record go in first.
  std::size_t i = 0;
  for (const TrajectoryRecord& r : traj.records) {
    while (i < truth.records.size() && truth.records[i].t + opt.truth_time_offset < r.t)
      ev.add_truth(truth.records[i++]);
    if (!move) {
      ev.add_trajectory(r);
      continue;
    }
    // p' = R p + t in the evaluation frame; attitude and velocity turned by R, the north/east
    // sigmas by its yaw (the diagonal of Rz P Rz^T).
    TrajectoryRecord m = r;
    const Vec3 p = traj.has_lla ? frame.ned_from_geodetic(r.lla) : r.p_inN;
    m.p_inN = move->R * p + move->t;
    m.lla = frame.geodetic_from_ned(m.p_inN);
    m.v_inN = move->R * r.v_inN;
    const Vec3 rpy = traj.has_roll_pitch ? r.rpy : Vec3(0.0, 0.0, r.rpy.z());
    m.rpy = euler_from_dcm(move->R * dcm_from_euler(rpy));
    if (!traj.has_roll_pitch) m.rpy.head<2>() = r.rpy.head<2>();
    const Eigen::Matrix2d Rz = rot_z(euler_from_dcm(move->R).z()).topLeftCorner<2, 2>();
    const Eigen::Matrix2d P = Rz * r.p_std.head<2>().cwiseAbs2().asDiagonal() * Rz.transpose();
    m.p_std.head<2>() = P.diagonal().cwiseSqrt();
    ev.add_trajectory(m);
  }
  ev.end_trajectory();
  while (i < truth.records.size()) ev.add_truth(truth.records[i++]);
  return ev.finish();
}

// The positions compared at the evaluated epochs: the trajectory's (at the antenna, as
// evaluated) in `traj_p`, the truth's in `truth_p`.
void evaluated_pairs(const EvalResult& r, const TruthData& truth, const earth::LocalFrame& frame, double offset,
                     std::vector<Vec3>& traj_p, std::vector<Vec3>& truth_p) {
  std::size_t i = 0;
  for (const EpochError& e : r.series) {
    while (i < truth.records.size() && truth.records[i].t + offset < e.t) ++i;
    if (i == truth.records.size() || truth.records[i].t + offset != e.t)
      throw std::logic_error("evaluate: an evaluated epoch without its truth record");
    const Vec3 p = frame.ned_from_geodetic(truth.records[i].lla);
    truth_p.push_back(p);
    traj_p.push_back(p + e.err_ned);
  }
}

}  // namespace

EvalResult evaluate(const TruthData& truth, const TrajectoryData& traj,
                    const earth::LocalFrame& frame, const EvalOptions& opt) {
  const bool fit = opt.align_fit != AlignFit::kNone;
  if (fit && (opt.align_origin || opt.align_start > 0.0))
    throw InputError("two alignments asked for: the whole trajectory's (se3/se2) and the " +
                     std::string(opt.align_origin ? "origin's" : "start's") + "; give one");
  EvalOptions first = opt;
  first.align_fit = AlignFit::kNone;
  EvalResult res = evaluate_pass(truth, traj, frame, first, nullptr);
  if (!fit && traj.format != TrajectoryFormat::kTum) return res;
  std::vector<Vec3> traj_p, truth_p;
  evaluated_pairs(res, truth, frame, opt.truth_time_offset, traj_p, truth_p);
  if (traj.format == TrajectoryFormat::kTum) {
    const MirrorCheck m = check_mirror(traj_p, truth_p);
    if (m.mirrored) {
      const char* read_as = tum_frame_name(traj.tum_frame);
      const char* other = traj.tum_frame == TumFrame::kNed ? "enu" : "ned";
      throw InputError(quote(traj.file) + ": its track is the mirror image of the truth's (a reflection fits it to " +
                       fixed(m.reflection_rms, 2) + " m rms, no rotation better than " + fixed(m.rotation_rms, 2) +
                       " m over " + std::to_string(m.points) + " epochs): a TUM file in ENU (x east, y north: "
                       "ROS, evo) read as NED, or the reverse. It was read as " + read_as +
                       (traj.frame_assumed ? " (the file has no frame line and none was given)" : "") +
                       "; give the frame it is in (--frame " + other + ")");
    }
  }
  if (!fit) return res;
  const RigidFit move = fit_rigid(traj_p, truth_p, opt.align_fit);
  if (!move.found)
    throw InputError(quote(traj.file) + ": aligning the whole trajectory needs at least 3 evaluated epochs, got " +
                     std::to_string(res.epochs));
  res = evaluate_pass(truth, traj, frame, first, &move);
  res.aligned = true;
  res.align_method = opt.align_fit == AlignFit::kSe3 ? "se3" : "se2";
  res.align_rotated = true;
  res.align_rpy = euler_from_dcm(move.R);
  res.align_yaw = res.align_rpy.z();
  res.align_offset = move.t;
  res.align_residual = move.rms;
  res.align_points = move.points;
  return res;
}

namespace {

void json_string(std::string& o, const std::string& s) { o += io_detail::json_quote(s); }

void json_number(std::string& o, double v) {
  if (!std::isfinite(v)) {
    o += "null";
    return;
  }
  append_double(o, v, 10);
}

void json_vec3(std::string& o, const Vec3& v) {
  o += '[';
  for (int k = 0; k < 3; ++k) {
    if (k) o += ", ";
    json_number(o, v[k]);
  }
  o += ']';
}

class JsonObject {
 public:
  explicit JsonObject(std::string& o) : o_(o) { o_ += "{\n"; }
  void key(const char* k) {
    if (!first_) o_ += ",\n";
    first_ = false;
    o_ += "  ";
    json_string(o_, k);
    o_ += ": ";
  }
  void num(const char* k, double v) {
    key(k);
    json_number(o_, v);
  }
  void count(const char* k, std::size_t v) {
    key(k);
    o_ += std::to_string(v);
  }
  void boolean(const char* k, bool v) {
    key(k);
    o_ += v ? "true" : "false";
  }
  void str(const char* k, const std::string& v) {
    key(k);
    json_string(o_, v);
  }
  void close() { o_ += "\n}\n"; }

 private:
  std::string& o_;
  bool first_ = true;
};

}  // namespace

std::string coverage_warning(const EvalResult& r) {
  if (r.comparable) return {};
  char buf[600];
  std::snprintf(buf, sizeof buf,
                "the figures are NOT comparable with a full trajectory's: the trajectory covers %.1f %% of "
                "the truth's %.1f s from the trajectory's start (%.1f s; %zu truth epochs outside it, %zu in its gaps longer than %.3g s, "
                "%zu between records sparser than the truth); the drift rate, errors and heading RMSE "
                "are for the covered part only",
                r.coverage * 100.0, r.truth_span, r.covered, r.skipped_outside, r.skipped_gap, r.max_gap,
                r.skipped_sparse);
  return buf;
}

std::string sigma_warning(const EvalResult& r) {
  if (!r.has_sigma || !(r.mean_nees > kOverconfidentNees)) return {};
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "the trajectory's 1-sigma figures understate its error: mean horizontal NEES %.1f, "
                "2 if consistent (the errors are about %.1fx the sigmas)",
                r.mean_nees, std::sqrt(r.mean_nees / 2.0));
  return buf;
}

std::string to_json(const EvalResult& r) {
  std::string o;
  JsonObject j(o);
  j.str("truth_file", r.truth_file);
  j.str("traj_file", r.traj_file);
  j.str("traj_format", r.traj_format);
  j.str("truth_layout", r.truth_layout);
  j.count("truth_records", r.truth_records);
  j.count("traj_records", r.traj_records);
  j.count("epochs", r.epochs);
  j.count("skipped_outside", r.skipped_outside);
  j.count("skipped_gap", r.skipped_gap);
  j.count("skipped_truth_jump", r.skipped_truth_jump);
  j.count("skipped_sparse", r.skipped_sparse);
  j.num("truth_span_s", r.truth_span);
  j.num("covered_s", r.covered);
  j.num("coverage_fraction", r.coverage);
  j.boolean("comparable", r.comparable);
  j.num("t_start_s", r.t_start);
  j.num("t_end_s", r.t_end);
  j.num("duration_s", r.duration);
  j.num("distance_m", r.distance);
  j.num("segment_m", r.segment_length);
  j.num("drift_rate_pct", r.drift_rate * 100.0);
  j.num("final_error_over_distance_pct", r.final_error_ratio * 100.0);
  j.key("drift_curve_pct");
  o += '[';
  for (std::size_t k = 0; k < r.drift_curve.size(); ++k) {
    if (k) o += ", ";
    json_number(o, r.drift_curve[k] * 100.0);
  }
  o += ']';
  j.str("heading_source", r.heading_source);
  j.count("heading_epochs", r.heading_epochs);
  j.num("heading_rmse_deg", r.heading_rmse / kDeg);
  j.num("heading_max_abs_deg", r.heading_max_abs / kDeg);
  j.num("max_error_m", r.max_error);
  j.num("final_error_m", r.final_error);
  j.num("rms_error_m", r.rms_error);
  j.boolean("has_sigma", r.has_sigma);
  j.count("sigma_epochs", r.sigma_epochs);
  j.num("within_3sigma_fraction", r.within_3sigma);
  j.num("mean_nees_h", r.mean_nees);
  j.boolean("aligned", r.aligned);
  j.str("align_method", r.align_method);
  j.boolean("align_rotated", r.align_rotated);
  j.num("align_yaw_deg", r.align_yaw / kDeg);
  j.num("align_start_m", r.align_start);
  j.num("align_residual_m", r.align_residual);
  j.key("align_offset_ned_m");
  json_vec3(o, r.align_offset);
  j.key("align_rotation_rpy_deg");
  json_vec3(o, r.align_rpy / kDeg);
  j.count("align_points", r.align_points);
  j.key("antenna_m");
  json_vec3(o, r.antenna);
  j.num("truth_time_offset_s", r.truth_time_offset);
  const TruthQualityReport& q = r.truth_quality;
  j.key("truth_quality");
  o += "{\"records\": " + std::to_string(q.records) + ", \"median_interval_s\": ";
  json_number(o, q.median_interval);
  o += ", \"gap_count\": " + std::to_string(q.gap_count) + ", \"stall_count\": " +
       std::to_string(q.stall_count) + ", \"gap_s\": ";
  json_number(o, q.gap_seconds);
  o += ", \"gap_distance_m\": ";
  json_number(o, q.gap_distance);
  o += ", \"jump_count\": " + std::to_string(q.jump_count) + ", \"bad_records\": " +
       std::to_string(q.bad_records) + ", \"repeated\": " + std::to_string(q.repeated) + ",\n    \"gaps\": [";
  for (std::size_t k = 0; k < q.gaps.size(); ++k) {
    o += k ? ", {\"t_from_s\": " : "{\"t_from_s\": ";
    json_number(o, q.gaps[k].t_from);
    o += ", \"t_to_s\": ";
    json_number(o, q.gaps[k].t_to);
    o += ", \"repeated\": " + std::to_string(q.gaps[k].repeated) + "}";
  }
  o += "],\n    \"jumps\": [";
  for (std::size_t k = 0; k < q.jumps.size(); ++k) {
    o += k ? ", {\"t_s\": " : "{\"t_s\": ";
    json_number(o, q.jumps[k].t);
    o += ", \"record\": " + std::to_string(q.jumps[k].record) + ", \"speed_m_s\": ";
    json_number(o, q.jumps[k].speed);
    o += ", \"accel_m_s2\": ";
    json_number(o, q.jumps[k].accel);
    o += "}";
  }
  o += "]}";
  j.close();
  return o;
}

}  // namespace wheelins::eval
