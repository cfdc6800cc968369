// The evaluation with the trajectory's start aligned onto the truth (aligned_evaluator.hpp).
#include "wheelins/eval/aligned_evaluator.hpp"

#include <cmath>

#include "wheelins/io/text_util.hpp"

namespace wheelins::eval {

StartAlignedEvaluator::StartAlignedEvaluator(const earth::LocalFrame& frame, const Evaluator::Sources& sources,
                                             const EvalOptions& options, bool keep_series)
    : frame_(frame), src_(sources), opt_(options), ev_(frame, sources, options, keep_series),
      collecting_(options.align_start > 0.0) {
  if (!(options.align_start >= 0.0 && options.align_start <= 1e6))
    throw InputError("the start alignment's length must be in [0, 1e6] m, got " + std::to_string(options.align_start));
  if (collecting_ && options.align_origin)
    throw InputError("two alignments asked for: the first epoch's (align) and the start's (align_start); give one");
  if (collecting_ && !sources.traj_has_heading)
    throw InputError(io_detail::quote(sources.traj_file) + ": aligning the start needs the trajectory's heading, "
                     "which it does not have");
}

Vec2 StartAlignedEvaluator::ne(const TrajectoryRecord& r) const {
  return src_.traj_has_lla ? Vec2(frame_.ned_from_geodetic(r.lla).head<2>()) : Vec2(r.p_inN.head<2>());
}

TrajectoryRecord StartAlignedEvaluator::transformed(const TrajectoryRecord& r) const {
  if (!alignment_.found) return r;
  TrajectoryRecord t = r;
  const Vec2 p = apply_alignment(alignment_, ne(r));
  const double down = src_.traj_has_lla ? frame_.ned_from_geodetic(r.lla).z() : r.p_inN.z();
  t.p_inN = Vec3(p.x(), p.y(), down);
  t.lla = frame_.geodetic_from_ned(t.p_inN);
  const double c = std::cos(alignment_.yaw), s = std::sin(alignment_.yaw);
  t.v_inN = Vec3(c * r.v_inN.x() - s * r.v_inN.y(), s * r.v_inN.x() + c * r.v_inN.y(), r.v_inN.z());
  t.rpy.z() = wrap_pi(r.rpy.z() + alignment_.yaw);
  // The north/east sigmas turned with the trajectory (the diagonal of R P R^T).
  const double sn2 = r.p_std.x() * r.p_std.x(), se2 = r.p_std.y() * r.p_std.y();
  t.p_std.x() = std::sqrt(c * c * sn2 + s * s * se2);
  t.p_std.y() = std::sqrt(s * s * sn2 + c * c * se2);
  return t;
}

void StartAlignedEvaluator::add_truth(const TruthRecord& r) {
  if (!collecting_) return ev_.add_truth(r);
  const Vec2 p = frame_.ned_from_geodetic(r.lla).head<2>();
  if (!truth_.empty() && !window_full_) travelled_ += (p - last_ne_).norm();
  last_ne_ = p;
  if (!window_full_ && travelled_ >= opt_.align_start) {
    window_full_ = true;
    window_end_ = r.t + opt_.truth_time_offset;
  }
  truth_.push_back(r);
}

void StartAlignedEvaluator::add_trajectory(const TrajectoryRecord& r) {
  if (!collecting_) return ev_.add_trajectory(transformed(r));
  traj_.push_back(r);
  if (window_full_ && r.t >= window_end_) release();
}

void StartAlignedEvaluator::end_trajectory() {
  if (collecting_) release();
  ev_.end_trajectory();
}

void StartAlignedEvaluator::release() {
  collecting_ = false;
  PlanarTrack ref, tr;
  for (const TruthRecord& r : truth_) {
    ref.t.push_back(r.t + opt_.truth_time_offset);
    ref.p_ne.push_back(frame_.ned_from_geodetic(r.lla).head<2>());
  }
  for (const TrajectoryRecord& r : traj_) {
    tr.t.push_back(r.t);
    tr.p_ne.push_back(ne(r));
    tr.heading.push_back(r.rpy.z());
  }
  StartAlignmentOptions o;
  o.length = opt_.align_start;
  o.antenna = Vec2(opt_.antenna.x(), opt_.antenna.y());
  alignment_ = fit_start_alignment(ref, tr, o);
  if (!alignment_.found)
    throw InputError("the trajectory's start could not be aligned onto the truth (" + std::to_string(alignment_.points) +
                     " common epochs in the first " + std::to_string(static_cast<int>(opt_.align_start)) +
                     " m; at least 5 are needed)");
  // In step, as the plain evaluation feeds them: the truth before each trajectory record.
  std::size_t i = 0;
  for (const TrajectoryRecord& r : traj_) {
    while (i < truth_.size() && truth_[i].t + opt_.truth_time_offset < r.t) ev_.add_truth(truth_[i++]);
    ev_.add_trajectory(transformed(r));
  }
  while (i < truth_.size()) ev_.add_truth(truth_[i++]);
  std::vector<TruthRecord>().swap(truth_);
  std::vector<TrajectoryRecord>().swap(traj_);
}

EvalResult StartAlignedEvaluator::finish() {
  EvalResult r = ev_.finish();
  if (alignment_.found) {
    r.aligned = true;
    r.align_method = "start";
    r.align_rotated = true;
    r.align_yaw = alignment_.yaw;
    r.align_offset = Vec3(alignment_.shift.x(), alignment_.shift.y(), 0.0);
    r.align_start = alignment_.length;
    r.align_residual = alignment_.rms;
  }
  return r;
}

}  // namespace wheelins::eval
