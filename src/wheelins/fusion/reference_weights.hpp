// The reference weights k_i of the position constraint (paper eq. 8, weightedpos). The
// paper weights the subsystems' reference points o equally and leaves weights from the
// data to future work. With ReferenceWeighting::kCovariance each subsystem weighs the
// inverse of the horizontal variance of its own o, tr_h(H_mlt P H_mlt^T) (H_mlt of
// position_constraint.hpp): the minimum-variance weights of independent estimates, so a
// noisier chip, whose covariance the noise identification lets grow faster, counts less.
// The variances are averaged (exponentially, over FusionOptions::weight_window constraint
// epochs) because a subsystem's P swings within each constraint interval and weights that
// follow it move the reference point by a share of the subsystems' disagreement every
// epoch. A module that stops counting (fault handling) keeps no weight; when it counts
// again its average starts afresh from its own new covariance. docs/filter.md section 14.
//
// Every constraint epoch's weights as used in eq. (8) (over the modules that count, 0 for
// the others) are recorded, with either weighting: the run writes them to weights.csv.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "wheelins/filter/position_constraint.hpp"
#include "wheelins/fusion/options.hpp"

namespace wheelins {

/// The weights of eq. (8) at one constraint epoch.
struct WeightRecord {
  double t = 0.0;
  std::array<double, kMaxModules> k{};  ///< sum 1 over the counted modules, 0 for the others
};

/// The horizontal variance of a subsystem's reference point o: the trace of the horizontal
/// 2x2 block of H_mlt P H_mlt^T (w-frame x, y) [m^2].
double reference_point_variance(const ReferencePointModel& r, const Mat21& P);

class ReferenceWeights {
 public:
  /// The smallest variance a weight is taken from (1 mm)^2: no subsystem's o is exact.
  static constexpr double kMinVariance = 1e-6;

  /// `configured`: the fixed weights (Subsystems::weight), used unless from_covariance().
  ReferenceWeights(const FusionOptions& options, const std::vector<double>& configured);

  bool from_covariance() const { return covariance_; }
  /// Subsystem i's o variance at this constraint epoch; `counted`: it is in the mean now.
  void observe(int i, double variance, bool counted);
  /// Subsystem i's relative weight now (> 0; not normalised).
  double weight(int i) const { return w_[i]; }
  const std::array<double, kMaxModules>& weights() const { return w_; }

  /// Records the weights eq. (8) used at time t.
  void record(double t, const std::array<double, kMaxModules>& k_used);
  const std::vector<WeightRecord>& history() const { return history_; }

 private:
  bool covariance_;
  double alpha_;  ///< 1 / window
  int n_;
  std::array<double, kMaxModules> w_{}, mean_var_{};
  std::array<bool, kMaxModules> averaging_{};  ///< mean_var_[i] holds an average
  std::vector<WeightRecord> history_;
};

/// The weights over a run, per module: the mean, least and greatest weight over the epochs
/// it counted, and the share of epochs it counted.
struct WeightSummary {
  double mean = 0.0, min = 0.0, max = 0.0, counted = 0.0;
};
std::vector<WeightSummary> summarize_weights(const std::vector<WeightRecord>& history, int n);

/// weights.csv: `t,<module>...`, one row per constraint epoch.
std::string weights_csv(const std::vector<WeightRecord>& history,
                        const std::vector<std::string>& modules);
/// A few lines for the run's printout: how the weights were made and their summary.
std::string weights_report(const std::vector<WeightRecord>& history,
                           const std::vector<std::string>& modules, const FusionOptions& options);

}  // namespace wheelins
