// The wheel-velocity aid of wheel_velocity_aid.hpp.
#include "wheelins/fusion/aids/wheel_velocity/wheel_velocity_aid.hpp"

namespace wheelins {

void WheelVelocityAid::begin_epoch(double t) {
  ctx_.faults.on_velocity_step(t);
  ctx_.act_on_faults();
  // Shared information (Section III): the vehicle level from the Body-INS, the wheel speed.
  ctx_.share_level();
}

void WheelVelocityAid::step(double t) {
  Subsystems& subs = ctx_.subs;
  SharedInputs& sh = ctx_.shared;
  take_level(subs, ctx_.level_shared(), false, sh);
  take_wheel_inputs(subs, ctx_.in_use(), sh);
  for (int i = 0; i < subs.size(); ++i)
    if (subs.is_wheel(i) && ctx_.faults.in_use(i))
      ctx_.faults.tally_speed(i, sh.wheel[i].measured_speed, schedule_.interval());
  select_speeds(t);
  take_mean_speed(subs, speeds_, sh);
  // The distributed filter's updates all use the step's shared quantities; the centralized
  // filter's sequential updates each see the state the previous one left (a joint correction
  // moves every IMU's errors), with the step's speed selection.
  const bool joint = ctx_.filter.joint();
  for (int i = 0; i < subs.size(); ++i) {
    if (!ctx_.faults.in_use(i)) continue;
    if (joint) {
      ctx_.share_level();
      take_speeds(sh, false);
    }
    wheelins::velocity_measurement(subs, sh, ctx_.opt.fusion, i, joint, ctx_.meas);
    ctx_.noise.prepare_velocity(i, ctx_.meas);
    const Vec3 bias_before = subs[i].ekf().errors().bg;
    const UpdateReport rep = ctx_.filter.fuse(ctx_.meas);
    ctx_.noise.after_velocity(i, ctx_.meas, rep, bias_before, t);
    stats_.count(rep);
    ctx_.faults.on_velocity_update(i, rep, t);
    ctx_.act_on_faults();
  }
}

void WheelVelocityAid::select_speeds(double t) {
  // Every wheel in use; the fault policy leaves out the unusable ones (saturated, slipping).
  const Subsystems& subs = ctx_.subs;
  const FaultHandler& faults = ctx_.faults;
  SpeedSelection& sel = speeds_;
  sel = SpeedSelection();
  for (int i = 0; i < subs.size(); ++i) sel.speed_ok[i] = subs.is_wheel(i) && faults.in_use(i);
  ctx_.faults.screen_speeds(t, ctx_.shared.wheel, sel);
  ctx_.act_on_faults();
  // The mean is over the usable speeds of the wheels that count; with none, the clipped
  // speeds of saturated wheels (lower bounds) are better than none.
  for (int i = 0; i < subs.size(); ++i)
    if (sel.speed_ok[i] && faults.counted(i)) {
      sel.in_mean[i] = true;
      ++sel.n_mean;
    }
  if (sel.n_mean == 0)
    for (int i = 0; i < subs.size(); ++i)
      if (sel.fallback[i] && faults.counted(i)) {
        sel.speed_ok[i] = sel.in_mean[i] = true;
        ++sel.n_mean;
      }
  // Unsteered wheels measure the vehicle's forward speed directly; a steered wheel's depends
  // on its estimated steering: it counts in the mean only when no unsteered wheel does.
  bool unsteered = false;
  for (int i = 0; i < subs.size(); ++i)
    unsteered = unsteered || (sel.in_mean[i] && !subs.wheel(i).steered());
  if (unsteered)
    for (int i = 0; i < subs.size(); ++i)
      if (sel.in_mean[i] && subs.wheel(i).steered()) {
        sel.in_mean[i] = false;
        --sel.n_mean;
      }
}

void WheelVelocityAid::take_speeds(SharedInputs& sh, bool level_now) const {
  take_level(ctx_.subs, ctx_.level_shared(), level_now, sh);
  take_wheel_inputs(ctx_.subs, ctx_.in_use(), sh);
  take_mean_speed(ctx_.subs, speeds_, sh);
}

void WheelVelocityAid::measurement(int i, Measurement& m) const {
  SharedInputs sh;
  take_speeds(sh, true);
  wheelins::velocity_measurement(ctx_.subs, sh, ctx_.opt.fusion, i, ctx_.filter.joint(), m);
}

}  // namespace wheelins
