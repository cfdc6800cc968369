// The streaming evaluation of a run (run_evaluation.hpp): the truth read in step with the
// vehicle records (one every kInterval s), a bad record held until finish().
#include "wheelins/eval/run_evaluation.hpp"

#include <limits>

#include "wheelins/nav/types.hpp"

namespace wheelins::eval {

RunEvaluation::RunEvaluation(const std::filesystem::path& truth_file, const earth::Geodetic& origin,
                             const RunEvaluationOptions& options)
    : truth_(std::make_unique<TruthReader>(truth_file, options.layout, options.truth)),
      truth_time_offset_(options.eval.truth_time_offset) {
  Evaluator::Sources src;
  src.truth_file = truth_->file().string();
  src.traj_file = options.solution;
  src.traj_format = "memory";
  src.truth_layout = truth_layout_name(truth_->layout());
  src.truth_has_attitude = truth_->has_attitude();
  src.truth_has_velocity = truth_->has_velocity();
  evaluator_ = std::make_unique<StartAlignedEvaluator>(earth::LocalFrame(origin), src, options.eval, options.keep_series);
  have_next_truth_ = truth_->next(next_truth_);
}

RunEvaluation::~RunEvaluation() = default;

void RunEvaluation::feed_truth_before(double t) {
  while (have_next_truth_ && next_truth_.t + truth_time_offset_ < t) {
    evaluator_->add_truth(next_truth_);
    have_next_truth_ = truth_->next(next_truth_);
  }
}

void RunEvaluation::add(const TrajectoryRecord& r) {
  if (!error_.empty() || r.t + 1e-9 < next_keep_) return;
  next_keep_ = r.t + kInterval;
  try {
    feed_truth_before(r.t);
    evaluator_->add_trajectory(r);
  } catch (const InputError& e) {
    error_ = e.what();
  }
}

EvalResult RunEvaluation::finish() {
  if (error_.empty()) {
    try {
      evaluator_->end_trajectory();
      feed_truth_before(std::numeric_limits<double>::infinity());
    } catch (const InputError& e) {
      error_ = e.what();
    }
  }
  if (!error_.empty()) throw InputError(error_);
  return evaluator_->finish();
}

}  // namespace wheelins::eval
