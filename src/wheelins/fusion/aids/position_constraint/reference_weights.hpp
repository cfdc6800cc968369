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
// Those covariances are the constraint's own product: each subsystem takes the fused
// reference as independent information, so every P shrinks at every constraint epoch and
// a Body-INS, whose heading the constraint alone makes observable, looks as good as the
// Wheel-INS it leans on. ReferenceWeighting::kStandalone weighs instead what each
// subsystem would drift on its own (StandaloneDrift): the weights of a federated filter
// without reset (Carlson 1990), whose local filters never see the fused solution, so
// their covariances stay honest. docs/filter.md section 14.1.
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

/// A subsystem's lateral drift without the position constraint, for the weights of
/// ReferenceWeighting::kStandalone: the covariance of [lateral position e (m), heading psi
/// (rad), vertical gyro bias b (rad/s), yaw-rate scale factor s (-)] under
///   e' = v psi,   psi' = b + omega s + w_arw,   b' = -b / tau + w_b,   s' = 0
/// (omega the vehicle's yaw rate; b a first-order Gauss-Markov process), the heading error
/// that no measurement of a subsystem's own observes (wheel speed and the non-holonomic
/// constraints see velocity in its own frame, not heading). A Body-IMU's vertical gyro bias
/// enters as it is (its variance at the start, then its instability); a Wheel-IMU's gyro
/// turns with the wheel, which modulates the bias of its two axes in the wheel plane to a
/// zero mean (the paper's rotation modulation), so its heading grows with the angle random
/// walk and its scale factor, which the rotation does not cancel: the mean of those two
/// axes' scale factors is its yaw-rate scale factor, and every turn the vehicle makes puts
/// s times the turned angle into the heading, for a Wheel-IMU as for a Body-IMU. The
/// common initial heading error is left out: it moves every subsystem alike and so no weight.
struct StandaloneDrift {
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  double t = 0.0;
  double heading = 0.0;  ///< the vehicle's heading at t [rad], for omega
  bool started = false;

  /// Starts at time t0 and vehicle heading `heading0` with the vertical bias variance
  /// `bias_var` [rad^2/s^2] (0: modulated) and the yaw-rate scale factor's `sf_var`.
  void start(double t0, double heading0, double bias_var, double sf_var);
  /// Propagates to time t1 and vehicle heading `heading1` (the yaw rate between is the
  /// heading's change over the time, wrapped) at ground speed `speed` [m/s]: angle random walk
  /// `arw` [rad/sqrt(s)]; the bias a Gauss-Markov process of sigma `bias_std` [rad/s] and
  /// correlation time `tau` [s] (bias_std 0: no bias, a Wheel-IMU). Steps of at most 1 s.
  void step(double t1, double heading1, double speed, double arw, double bias_std, double tau);
  double lateral_variance() const { return P(0, 0); }
};

class ReferenceWeights {
 public:
  /// The smallest variance a weight is taken from (1 mm)^2: no subsystem's o is exact.
  static constexpr double kMinVariance = 1e-6;

  /// `configured`: the fixed weights (Subsystems::weight), used unless from_covariance().
  ReferenceWeights(const FusionOptions& options, const std::vector<double>& configured);

  bool from_covariance() const { return covariance_; }
  bool from_standalone() const { return standalone_; }
  /// Subsystem i's o variance at this constraint epoch; `counted`: it is in the mean now.
  void observe(int i, double variance, bool counted);
  /// kStandalone: subsystem i's constraint-free drift at time t and vehicle heading
  /// `heading` (its own noise model `q`; `bias_var0` the variance of its vertical gyro bias
  /// when it first counts, 0 for a Wheel-IMU; `sf_var0` its yaw-rate scale factor's). Its
  /// weight is the inverse of its lateral variance; it keeps growing through an outage (the
  /// drift of a subsystem left to itself).
  void observe_standalone(int i, double t, double heading, double speed, const ImuNoise& q, bool wheel,
                          double bias_var0, double sf_var0);
  const StandaloneDrift& drift(int i) const { return drift_[i]; }
  /// Subsystem i's relative weight now (> 0; not normalised).
  double weight(int i) const { return w_[i]; }
  const std::array<double, kMaxModules>& weights() const { return w_; }

  /// Records the weights eq. (8) used at time t.
  void record(double t, const std::array<double, kMaxModules>& k_used);
  const std::vector<WeightRecord>& history() const { return history_; }

 private:
  bool covariance_, standalone_;
  double alpha_;  ///< 1 / window
  int n_;
  std::array<double, kMaxModules> w_{}, mean_var_{};
  std::array<bool, kMaxModules> averaging_{};  ///< mean_var_[i] holds an average
  std::array<StandaloneDrift, kMaxModules> drift_{};
  std::vector<WeightRecord> history_;
};

/// The weights over a run, per module: the mean, least and greatest weight over the epochs
/// it counted, and the share of epochs it counted.
struct WeightSummary {
  double mean = 0.0, min = 0.0, max = 0.0, counted = 0.0;
  /// A steered wheel that follows (Subsystems::follows): tied to the reference, never in it.
  bool follows = false;
};
/// `follows[i]`: module i is a steered wheel that follows (may be empty: none).
std::vector<WeightSummary> summarize_weights(const std::vector<WeightRecord>& history, int n,
                                             const std::vector<bool>& follows = {});

/// weights.csv: `t,<module>...`, one row per constraint epoch.
std::string weights_csv(const std::vector<WeightRecord>& history,
                        const std::vector<std::string>& modules);
/// A few lines for the run's printout: how the weights were made and their summary `s`
/// (summarize_weights) over `epochs` constraint epochs ("" when there were none).
std::string weights_report(const std::vector<WeightSummary>& s, std::size_t epochs,
                           const std::vector<std::string>& modules, const FusionOptions& options);

}  // namespace wheelins
