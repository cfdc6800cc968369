// The zero-motion aid of zero_motion_aid.hpp.
#include "wheelins/fusion/aids/zero_motion/zero_motion_aid.hpp"

namespace wheelins {

void ZeroMotionAid::step() {
  const StandstillOptions& o = ctx_.opt.standstill;
  for (int i = 0; i < ctx_.subs.size(); ++i) {
    if (!ctx_.faults.in_use(i) || !standstill_.quiet(i)) continue;
    wheelins::zero_velocity_measurement(ctx_.subs, i, o.velocity_std, ctx_.meas);
    ctx_.filter.fuse(ctx_.meas);
    wheelins::zero_rate_measurement(ctx_.subs, i, standstill_.mean_raw_rate(i), standstill_.window(i),
                                    o.rate_std, ctx_.meas);
    ctx_.filter.fuse(ctx_.meas);
    updates_ += 2;
  }
  ++steps_;
}

}  // namespace wheelins
