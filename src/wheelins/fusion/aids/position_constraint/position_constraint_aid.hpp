// The position-constraint aid (paper Section III-B, Algorithm 1, eq. 7, 8, 11): at every
// constraint epoch the weighted mean of the subsystems' reference points o (eq. 8) over the
// modules the fault policy counts is a position measurement for each module it ties to the
// others; modules on probation are tied without moving the reference. It owns its schedule
// (fusion.position_update_interval), the reference weights (reference_weights.hpp: equal,
// from the covariances or from each IMU's stand-alone drift; their history), the noise
// adaptation's hook after each fusion, the fault policy's step hook, and its statistics.
#pragma once

#include <vector>

#include "wheelins/fusion/aids/aid.hpp"
#include "wheelins/fusion/aids/position_constraint/reference_weights.hpp"

namespace wheelins {

class PositionConstraintAid {
 public:
  explicit PositionConstraintAid(const AidContext& ctx);

  AidSchedule& schedule() { return schedule_; }
  /// Whether the constraint runs at all: more than one subsystem and the option on.
  bool active() const { return ctx_.subs.size() > 1 && ctx_.opt.fusion.position_constraint; }
  /// The constraint now (every covariance at the time of the subsystem in use furthest behind).
  void step();
  /// Subsystem i's measurement as this aid would fuse it now (the level now).
  void measurement(int i, Measurement& m) const;
  const AidStats& stats() const { return stats_; }
  AidStats& stats() { return stats_; }
  /// The reference weights of eq. (8) at every constraint epoch.
  const std::vector<WeightRecord>& weight_history() const { return weights_.history(); }

 private:
  /// The reference weights k (eq. 8) renormalised over the counted modules (0 for the
  /// others); false when no module counts.
  bool reference_weights(std::array<double, kMaxModules>& k, int& n_ref, int& n_tied) const;
  /// ReferenceWeighting::kCovariance / kStandalone: the weights from every subsystem's o
  /// variance or stand-alone drift, which become the subsystems' k_i (Subsystems::set_weights)
  /// for this epoch on.
  void update_weights();
  void take_reference(SharedInputs& sh, bool level_now) const;

  AidContext ctx_;
  AidSchedule schedule_;
  ReferenceWeights weights_;
  AidStats stats_;
};

}  // namespace wheelins
