// The zero-motion aid (docs/faults.md, "Standing still"): while the vehicle stands, at a
// velocity-update epoch every quiet subsystem in use fuses zero velocity and zero angular
// rate instead of its wheel-speed update. It owns the standstill detector (standstill.hpp),
// fed every navigated sample, and its statistics. Not tested by the fault detector: a
// standing vehicle's innovations are not evidence against a module (and its wheel speeds
// not against the others').
#pragma once

#include "wheelins/fusion/aids/aid.hpp"
#include "wheelins/fusion/aids/zero_motion/standstill.hpp"

namespace wheelins {

class ZeroMotionAid {
 public:
  explicit ZeroMotionAid(const AidContext& ctx) : ctx_(ctx) { standstill_.configure(ctx.opt.standstill); }

  /// Module i's navigated sample (b-frame), with its filter's current sensor errors.
  void add(int i, const ImuSample& b) { standstill_.add(i, b, ctx_.subs[i].ekf().errors()); }
  /// At a velocity-update epoch at time t: whether the vehicle (the modules it is made of)
  /// stands.
  bool standing(double t) { return standstill_.evaluate(ctx_.counted_modules(), ctx_.subs.size(), t); }
  /// The zero velocity and rate updates of every quiet subsystem in use.
  void step();
  /// Updates fused and epochs at which the vehicle stood.
  std::uint64_t updates() const { return updates_; }
  std::uint64_t steps() const { return steps_; }

 private:
  AidContext ctx_;
  StandstillDetector standstill_;
  std::uint64_t updates_ = 0, steps_ = 0;
};

}  // namespace wheelins
