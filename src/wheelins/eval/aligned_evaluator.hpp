// The evaluation of a trajectory whose start is aligned onto the truth first
// (EvalOptions::align_start > 0): the truth and trajectory records are held until the
// truth has travelled align_start metres (and the trajectory has reached that time), the
// rotation and shift that carry the trajectory's start onto the truth's are fitted
// (eval/alignment.hpp; the antenna lever arm as given), and every trajectory record, held
// or later, is evaluated rotated and shifted -- its heading turned by the same angle. With
// align_start 0 it is the plain Evaluator. Memory: the records of the alignment window.
#pragma once

#include <memory>
#include <vector>

#include "wheelins/eval/alignment.hpp"
#include "wheelins/eval/metrics.hpp"

namespace wheelins::eval {

class StartAlignedEvaluator {
 public:
  StartAlignedEvaluator(const earth::LocalFrame& frame, const Evaluator::Sources& sources, const EvalOptions& options,
                        bool keep_series);
  void add_truth(const TruthRecord& r);
  void add_trajectory(const TrajectoryRecord& r);
  void end_trajectory();
  EvalResult finish();
  /// The alignment applied (found false while still collecting, or without align_start).
  const StartAlignment& alignment() const { return alignment_; }

 private:
  void release();
  TrajectoryRecord transformed(const TrajectoryRecord& r) const;
  Vec2 ne(const TrajectoryRecord& r) const;

  earth::LocalFrame frame_;
  Evaluator::Sources src_;
  EvalOptions opt_;
  Evaluator ev_;
  bool collecting_;
  std::vector<TruthRecord> truth_;
  std::vector<TrajectoryRecord> traj_;
  double travelled_ = 0.0, window_end_ = 0.0;
  bool window_full_ = false;
  Vec2 last_ne_ = Vec2::Zero();
  StartAlignment alignment_;
};

}  // namespace wheelins::eval
