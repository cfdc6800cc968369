// The evaluation `wheelins run` makes as it runs (and the Python module's run()):
// the truth file is streamed in step with the vehicle solution, taken every
// kInterval seconds, so memory stays flat however long the data. A truth file that
// cannot be opened, or whose first record is bad, throws from the constructor
// (before the run); a bad record met later is held and thrown by finish(), so the
// caller can write the trajectory first.
//
// Every truth layout streams (truth.hpp's TruthReader reads text and TUM line by line):
// the memory held is the truth records within the course baseline (1 s, where the truth
// has no heading) plus those between two evaluated vehicle records, kMedianWindow intervals
// of the quality checks and the listed gaps and jumps -- not the file.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "wheelins/eval/aligned_evaluator.hpp"
#include "wheelins/eval/metrics.hpp"
#include "wheelins/io/truth.hpp"

namespace wheelins::eval {

/// How the truth is read and compared (the defaults are what `wheelins run` always did).
struct RunEvaluationOptions {
  TruthLayout layout = TruthLayout::kAuto;
  TruthReadOptions truth{};  ///< time scale and offset on read, text columns, TUM frame and origin
  EvalOptions eval{};      ///< antenna lever arm, truth time offset, segment length, ...
  bool keep_series = false;  ///< the per-epoch errors in EvalResult::series (studies' plots)
  std::string solution = "the run's vehicle solution";  ///< names the trajectory in messages
};

class RunEvaluation {
 public:
  static constexpr double kInterval = 0.05;  ///< [s] between the records evaluated (20 Hz)

  RunEvaluation(const std::filesystem::path& truth_file, const earth::Geodetic& origin,
                const RunEvaluationOptions& options = {});
  ~RunEvaluation();
  RunEvaluation(const RunEvaluation&) = delete;
  RunEvaluation& operator=(const RunEvaluation&) = delete;

  /// Every vehicle record of the run, in time order (RunRequest::on_record).
  void add(const TrajectoryRecord& r);
  /// The metrics after the run; InputError for a bad truth record met on the way.
  EvalResult finish();
  const TruthReader& truth() const { return *truth_; }

 private:
  void feed_truth_before(double t);
  std::unique_ptr<TruthReader> truth_;
  std::unique_ptr<StartAlignedEvaluator> evaluator_;
  double truth_time_offset_ = 0.0;
  TruthRecord next_truth_;
  bool have_next_truth_ = false;
  double next_keep_ = -1e300;
  std::string error_;
};

}  // namespace wheelins::eval
