// Accuracy of a navigation result against a reference trajectory (paper
// Section VI-B): position drift rate, heading RMSE, and consistency figures.
//
// Definitions (all horizontal quantities use north/east in the local NED frame):
//  * Sampling: the trajectory is interpolated to the truth epochs, not the other
//    way round. The reference defines where and when accuracy is measured, so the
//    figures do not depend on the output rate of the tool being judged (a 1 Hz and
//    a 200 Hz result of the same filter score alike), and interpolating the
//    usually denser navigation output costs less than interpolating the truth.
//    Position, velocity-free: linear in NED; heading: along the shorter arc; 1-sigma
//    values: linear. Truth epochs outside the trajectory's time span are skipped
//    (no extrapolation), as are epochs whose bracketing trajectory records are more
//    than `max_gap` seconds apart (an output gap is not evidence of accuracy).
//  * Rate: the trajectory is interpolated only between records at most
//    max(kDenseInterval, 1.5 x the truth's record interval) apart. Sparser records (e.g.
//    `run --output-interval 5` against a 200 Hz truth) are scored only at the truth epochs
//    within kCoincide (1 ms) of a record, the record's own values against the truth's;
//    the truth epochs between them are skipped (skipped_sparse): a straight line through
//    records seconds apart is not the path, nor the heading, the tool computed.
//  * Coverage: covered = the time between consecutive scored epochs no more than
//    `max_gap` apart; coverage = covered / the truth's time span from the trajectory's first
//    record on (a run navigates from the end of its static period; a trajectory that ends
//    early or has gaps is what is caught). Below kMinCoverage the
//    result is marked not comparable (comparable = false, coverage_warning()): the figures
//    describe the covered part only (a trajectory with most records missing, or two
//    records, scores a small drift rate).
//  * Frames: positions are compared in the truth point's own north/east/down (the error
//    vector rotated from the evaluation frame, exact), and the truth's path length, course
//    and quality checks are taken in the truth's own frames, so that for a lat/lon
//    trajectory no figure depends on the evaluation frame's origin (evaluate --origin).
//  * Distance: s(t) = horizontal path length along the truth, accumulated over
//    consecutive truth records from the first evaluated epoch (horizontal, so the
//    height noise of the reference does not add distance while standing).
//  * Horizontal error: e_h = |(n_traj - n_truth, e_traj - e_truth)|.
//  * Drift rate (paper VI-B): with l the segment length and K = floor(s_total / l),
//    for k = 1..K:  r_k = max{ e_h(t) : s(t) <= k l } / (k l);
//    the drift rate is mean(r_1..r_K). Undefined (NaN) when s_total < l.
//  * Heading error: wrap(heading_traj - heading_ref) into (-180, 180] deg; RMSE over the
//    evaluated epochs that have both. Needs a trajectory heading. heading_ref is
//      - the truth's heading where the truth has attitude (11-column, TUM): source "truth";
//      - otherwise (5-column, text) the truth's course, the direction of its horizontal
//        motion: source "course". At a truth epoch t_i it is the direction from the last
//        good fix at or before t_i - B/2 to the first good fix at or after t_i + B/2
//        (B = course_baseline, 1 s; a chord centred on t_i is parallel to the tangent of a
//        circular arc), taken only where the speed along that chord is at least
//        course_min_speed (1 m/s) and no truth gap or step lies between the two fixes. It is
//        the vehicle's heading only while the vehicle drives forward without side slip (a
//        car reversing reads 180 deg off). With an antenna lever arm l the antenna's course
//        leads the heading in turns by asin(yaw_rate * l_x / V) (l_x the lever arm's forward
//        component with the trajectory's roll and pitch taken off, V the antenna's speed
//        along the chord, yaw_rate the trajectory's); that is taken off.
//    heading_rmse and heading_max_abs are over the epochs with a heading_ref.
//  * 1-sigma consistency (when the trajectory carries north/east std):
//    P = diag(sigma_n^2, sigma_e^2) (rotated with the trajectory when aligned),
//    sigma_h = sqrt(trace P) = sqrt(sigma_n^2 + sigma_e^2), the RMS of e_h that P
//    predicts. "Within 3 sigma" counts epochs with e_h <= 3 sigma_h; for a
//    consistent filter this fraction is >= 8/9 whatever P (Markov's inequality on
//    e_h^2) and 1 - exp(-4.5) = 0.989 for sigma_n = sigma_e.
//    Horizontal NEES = [dn de] P^-1 [dn de]^T, mean over epochs (2 if consistent).
//    Epochs with sigma_n or sigma_e not positive and finite are left out of both.
//  * Final error over distance: final_error / distance (fraction; shown in %), next to the
//    drift rate: the end-point figure many papers quote.
//  * Antenna: with `antenna` l (vehicle frame: x forward, y right, z down, from the
//    trajectory's reference point) the trajectory is moved to the antenna before anything
//    else: p_ant = p + C_v^n(roll, pitch, heading) l, with the trajectory's attitude (roll
//    and pitch 0 where it has none; a lever arm without a trajectory heading is an error).
//  * Truth time offset: truth_time_offset [s] is added to every truth time.
//  * Truth quality (truth_quality.hpp): the truth records are checked as they come; a
//    jumped fix (and its repeats) is left out of every figure and counted
//    (skipped_truth_jump); gaps, stalls and jumps are listed in truth_quality. A truth gap
//    holds no truth epochs, so nothing is scored inside it; the course is not taken across
//    it and the distance counts the straight line across it (truth_quality.gap_distance).
//  * Alignment of the origin (align_origin; evo's --align_origin, for results in another
//    tool's frame): the trajectory is rotated about the vertical through its position at the
//    first evaluated epoch by dpsi = wrap(heading_truth - heading_traj) there, and shifted so
//    that position equals the truth's; heading_traj += dpsi. Without headings on both sides
//    only the shift is applied (reported).
//  * Alignment of the whole trajectory (align_fit; evo's --align, evaluate() only): the
//    trajectory is evaluated once as it is, the rotation and translation that carry its
//    positions at the evaluated epochs onto the truth's are fitted (rigid_fit.hpp: SE(3), or
//    SE(2) = about the vertical only), and it is evaluated again moved by them (attitude and
//    velocity turned, north/east sigmas turned by the fit's yaw).
//  * Frame check (evaluate() only, TUM trajectories): a trajectory whose horizontal track is
//    the mirror image of the truth's (rigid_fit.hpp, check_mirror) is an InputError: an ENU
//    file read as NED or the reverse, which no rotation undoes.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/eval/rigid_fit.hpp"
#include "wheelins/eval/truth_quality.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/io/truth.hpp"

namespace wheelins::eval {

/// The drift-rate segment length's range [m]: the curve has distance / l entries.
constexpr double kMinSegment = 1.0, kMaxSegment = 1e6;
/// [s] trajectory records at most this far apart (or 1.5 truth intervals) are interpolated.
constexpr double kDenseInterval = 0.2;
/// The least coverage (covered time / the truth's span) of a comparable result.
constexpr double kMinCoverage = 0.9;

struct EvalOptions {
  double segment_length = 100.0;  ///< l [m] of the drift rate
  bool align_origin = false;      ///< shift + rotate the trajectory onto the truth at the first epoch
  /// > 0: the trajectory's start is aligned onto the truth's over this much of the truth's
  /// travel [m] (a run without an initial heading; eval/alignment.hpp, StartAlignedEvaluator).
  double align_start = 0.0;
  double max_gap = 5.0;           ///< [s] largest trajectory gap interpolated across
  /// The antenna (the truth's point) in the vehicle frame from the trajectory's reference
  /// point [m]: x forward, y right, z down.
  Vec3 antenna = Vec3::Zero();
  double truth_time_offset = 0.0;  ///< [s] added to every truth time
  double course_baseline = 1.0;    ///< B [s] of the course heading, in (0, 60]
  double course_min_speed = 1.0;   ///< [m/s] slowest truth motion whose course is used
  TruthQualityOptions truth_quality{};  ///< the thresholds of the truth quality checks
  /// Fit the whole trajectory onto the truth (evaluate() only; see the header).
  AlignFit align_fit = AlignFit::kNone;
};

/// The comparison at one evaluated truth epoch.
struct EpochError {
  double t = 0.0;
  double distance = 0.0;  ///< s(t) [m]
  Vec3 err_ned = Vec3::Zero();  ///< trajectory - truth [m]
  double err_h = 0.0;           ///< horizontal error [m]
  double heading_err = 0.0;     ///< [rad], NaN when not available
  double sigma_h = 0.0;         ///< [m], NaN when not available
  double nees_h = 0.0;          ///< NaN when not available
};

struct EvalResult {
  std::string truth_file, traj_file, traj_format;
  std::string truth_layout;           ///< Sources::truth_layout (empty when not given)
  std::size_t truth_records = 0, traj_records = 0;
  std::size_t epochs = 0;             ///< evaluated truth epochs
  std::size_t skipped_outside = 0;    ///< truth epochs outside the trajectory's time span
  std::size_t skipped_gap = 0;        ///< truth epochs inside a trajectory gap > max_gap
  std::size_t skipped_truth_jump = 0; ///< truth epochs left out: a jumped fix or its repeat
  std::size_t skipped_sparse = 0;     ///< truth epochs between records sparser than the truth
  double max_gap = 5.0;               ///< EvalOptions::max_gap [s]
  double truth_span = 0.0;            ///< last truth time - max(first truth, first trajectory time) [s]
  double covered = 0.0;               ///< time between scored epochs <= max_gap apart [s]
  double coverage = 1.0;              ///< covered / truth_span
  bool comparable = true;             ///< coverage >= kMinCoverage
  double t_start = 0.0, t_end = 0.0, duration = 0.0;  ///< evaluated span [s]
  double distance = 0.0;              ///< s_total [m]
  double segment_length = 100.0;
  std::vector<double> drift_curve;    ///< r_k, k = 1..K (fractions, not %)
  double drift_rate = 0.0;            ///< mean r_k (fraction); NaN if K = 0
  bool has_heading = false;
  /// Where heading_ref comes from: "truth" (its attitude), "course" (its motion) or "none".
  std::string heading_source = "none";
  std::size_t heading_epochs = 0;     ///< epochs with a heading error
  double heading_rmse = 0.0;          ///< [rad]; NaN without headings
  double heading_max_abs = 0.0;       ///< [rad]; NaN without headings
  double max_error = 0.0, final_error = 0.0, rms_error = 0.0;  ///< horizontal [m]
  double final_error_ratio = 0.0;     ///< final_error / distance (fraction); NaN at distance 0
  Vec3 antenna = Vec3::Zero();        ///< EvalOptions::antenna [m]
  double truth_time_offset = 0.0;     ///< EvalOptions::truth_time_offset [s]
  TruthQualityReport truth_quality;   ///< over every truth record fed
  bool has_sigma = false;
  std::size_t sigma_epochs = 0;       ///< epochs with usable north/east sigma
  double within_3sigma = 0.0;         ///< fraction in [0, 1]; NaN without sigma
  double mean_nees = 0.0;             ///< NaN without sigma
  bool aligned = false;
  /// "origin", "start", "se3", "se2" (the alignment applied) or "" (none).
  std::string align_method;
  bool align_rotated = false;         ///< heading part applied
  double align_yaw = 0.0;             ///< dpsi [rad]
  Vec3 align_offset = Vec3::Zero();   ///< truth - trajectory position at the pivot [m]; start alignment: its shift
  double align_start = 0.0;           ///< [m] of truth travel the start alignment used (0: none)
  double align_residual = 0.0;        ///< [m] rms of the start alignment's or the se3/se2 fit
  Vec3 align_rpy = Vec3::Zero();      ///< se3/se2: the fitted rotation as roll, pitch, yaw [rad]
  std::size_t align_points = 0;       ///< se3/se2: the epochs fitted
  std::vector<EpochError> series;     ///< one entry per evaluated epoch
};

/// A mean horizontal NEES above this is reported as sigmas that understate the error (by
/// more than sqrt(10 / 2) = 2.2x). A consistent filter's is 2; over one run, whose epochs are
/// correlated, our consistent filters measure 2.4-5.9 (docs/accuracy.md).
constexpr double kOverconfidentNees = 10.0;

/// "the trajectory's 1-sigma figures understate its error: ..." when the mean horizontal NEES
/// is above kOverconfidentNees; empty otherwise (or without sigmas).
std::string sigma_warning(const EvalResult& result);

/// "the figures are NOT comparable ..." when the result is not comparable (coverage below
/// kMinCoverage); empty otherwise.
std::string coverage_warning(const EvalResult& result);

/// r_k = max{err[i] : s[i] <= k l} / (k l) for k = 1..floor(s.back() / l), with s
/// non-decreasing distances from 0. Empty when s.back() < l.
std::vector<double> drift_rate_curve(const std::vector<double>& s, const std::vector<double>& err,
                                     double segment_length);

/// The evaluation of evaluate(), fed record by record. The truth and the trajectory
/// are each fed in time order, a truth record before any trajectory record later than
/// it; the evaluator keeps only the last two trajectory samples and the truth records
/// not yet bracketed by them, so its memory is constant when the two are fed in step
/// (the per-epoch series is kept only on request). The definitions are those above.
class Evaluator {
 public:
  struct Sources {
    std::string truth_file, traj_file, traj_format;
    std::string truth_layout;        ///< for the result (truth_layout_name()); may be empty
    bool truth_has_attitude = true;  ///< truth headings available (else the course is used)
    bool truth_has_velocity = true;  ///< truth velocities available (standing still is known)
    bool traj_has_lla = true;        ///< trajectory positions from lla (else p_inN)
    bool traj_has_heading = true;
    bool traj_has_roll_pitch = true; ///< roll and pitch for the antenna lever arm
    bool traj_has_sigma = true;      ///< north/east 1-sigma in p_std
  };
  /// Throws InputError for options out of range, and for an antenna lever arm without a
  /// trajectory heading.
  Evaluator(const earth::LocalFrame& frame, const Sources& sources, const EvalOptions& options,
            bool keep_series);
  ~Evaluator();
  Evaluator(const Evaluator&) = delete;
  Evaluator& operator=(const Evaluator&) = delete;

  /// The next truth record, as read (EvalOptions::truth_time_offset is added here: a
  /// feeder compares r.t + truth_time_offset with the trajectory's times).
  void add_truth(const TruthRecord& r);
  void add_trajectory(const TrajectoryRecord& r);
  /// No trajectory records follow: the truth records still to come are evaluated (or
  /// counted as outside) as they arrive instead of waiting, so feeding the rest of a long
  /// truth file keeps memory flat.
  void end_trajectory();
  /// Truth records held: waiting for the trajectory to reach them, or for the truth fixes
  /// after them (course_baseline / 2 later) where the heading comes from the course.
  std::size_t pending() const;
  /// The result; InputError (naming the files) when no truth epoch fell inside the
  /// trajectory.
  EvalResult finish();

 private:
  struct State;
  std::unique_ptr<State> s_;
};

/// Compares `traj` with `truth` in `frame` (the local NED frame both are expressed
/// in). Trajectory records with lat/lon/h are mapped into `frame`; records with
/// only north/east/down are taken as already in `frame`. The truth's heading is used
/// where it has attitude (TruthData::has_attitude), its course otherwise. Throws
/// InputError (naming the files) when no truth epoch falls inside the trajectory, or for
/// options out of range.
EvalResult evaluate(const TruthData& truth, const TrajectoryData& traj,
                    const earth::LocalFrame& frame, const EvalOptions& options = {});

/// The result as a JSON object (angles in degrees, rates in percent; NaN -> null;
/// the per-epoch series is left out).
std::string to_json(const EvalResult& result);

}  // namespace wheelins::eval
