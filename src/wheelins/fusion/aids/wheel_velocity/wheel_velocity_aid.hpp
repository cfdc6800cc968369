// The wheel-velocity aid (paper Section III, eq. 5, 6): at every velocity-update epoch each
// subsystem in use fuses its velocity + NHC measurement, the wheel speed shared (the mean
// over the Wheel-INSs the fault policy lets count, or each wheel's own). It owns its schedule
// (wheel.velocity_update_interval), its inputs (the speed selection of the step), the noise
// adaptation's hooks around each fusion, the fault policy's speed screening and report, and
// its statistics. While the vehicle stands the zero-motion aid steps instead (the navigator
// asks it first; zero_motion/).
#pragma once

#include "wheelins/fusion/aids/aid.hpp"

namespace wheelins {

class WheelVelocityAid {
 public:
  explicit WheelVelocityAid(const AidContext& ctx)
      : ctx_(ctx), schedule_(ctx.opt.wheel.velocity_update_interval) {}

  AidSchedule& schedule() { return schedule_; }
  /// The fault policy is told of the step and the Body-INS level is shared: the start of every
  /// velocity-update epoch, before the zero-motion aid decides whether the vehicle stands.
  void begin_epoch(double t);
  /// The velocity + NHC updates of every module in use at time t (every covariance at t).
  void step(double t);
  /// Subsystem i's measurement as this aid would fuse it now (the level now, the speed
  /// selection of the last step).
  void measurement(int i, Measurement& m) const;
  const AidStats& stats() const { return stats_; }
  AidStats& stats() { return stats_; }

 private:
  /// The wheel speeds of this step: the paper's mean over the wheels, less what the fault
  /// policy screens out.
  void select_speeds(double t);
  /// The shared quantities of the step (the speed selection) at the current state.
  void take_speeds(SharedInputs& sh, bool level_now) const;

  AidContext ctx_;
  AidSchedule schedule_;
  SpeedSelection speeds_;  ///< the wheel speeds usable at the last step
  AidStats stats_;
};

}  // namespace wheelins
