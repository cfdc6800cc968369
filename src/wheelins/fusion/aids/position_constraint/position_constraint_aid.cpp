// The position-constraint aid of position_constraint_aid.hpp.
#include "wheelins/fusion/aids/position_constraint/position_constraint_aid.hpp"

namespace wheelins {

namespace {
std::vector<double> configured_weights(const Subsystems& subs) {
  std::vector<double> w(subs.size());
  for (int i = 0; i < subs.size(); ++i) w[i] = subs.weight(i);
  return w;
}
}  // namespace

PositionConstraintAid::PositionConstraintAid(const AidContext& ctx)
    : ctx_(ctx),
      schedule_(ctx.opt.fusion.position_update_interval),
      weights_(ctx.opt.fusion, configured_weights(ctx.subs)) {}

void PositionConstraintAid::step() {
  // Algorithm 1 over the modules in good health: their weighted mean of o (eq. 8) is the
  // reference; modules on probation and steered wheels that follow are tied to it without
  // moving it.
  SharedInputs& sh = ctx_.shared;
  int n_ref = 0, n_tied = 0;
  if (weights_.from_covariance() || weights_.from_standalone()) update_weights();
  const bool have_ref = reference_weights(sh.k, n_ref, n_tied);
  // (The time of each is taken when it is asked: the fault policy may take a module in or out.)
  ctx_.faults.on_position_step(ctx_.min_time());
  ctx_.act_on_faults();
  if (have_ref) weights_.record(ctx_.min_time(), sh.k);
  if (!have_ref || n_tied < 2) return;
  // Distributed: every subsystem's o at the level the Wheel-INSs were last given; centralized:
  // each update re-evaluated at the state the previous one left.
  const bool joint = ctx_.filter.joint();
  if (!joint) take_reference(sh, false);
  for (int i = 0; i < ctx_.subs.size(); ++i) {
    // A lone reference module is not constrained by itself.
    if (!ctx_.faults.tied(i) || (n_ref == 1 && sh.k[i] > 0.0)) continue;
    if (joint) {
      ctx_.share_level();
      take_reference(sh, false);
    }
    wheelins::position_measurement(ctx_.subs, sh, ctx_.opt.fusion, i, ctx_.meas);
    const UpdateReport rep = ctx_.filter.fuse(ctx_.meas);
    ctx_.noise.after_position(i, rep);
    stats_.count(rep);
  }
}

void PositionConstraintAid::update_weights() {
  Subsystems& subs = ctx_.subs;
  Mat21 scratch;
  if (weights_.from_standalone()) {
    const double t = ctx_.min_time();
    for (int i = 0; i < subs.size(); ++i) {
      const Subsystem& s = subs[i];
      double bias_var0 = 0.0, sf_var0 = 0.0;
      if (!weights_.drift(i).started) {
        const Mat21& P = ctx_.filter.covariance(i, scratch);
        if (!s.is_wheel()) {
          // The body's vertical gyro bias variance as its filter holds it now (after the
          // alignment): u^T P_bg u with u the vertical in the b-frame.
          const Vec3 u = s.reference_point_input().C_BtoW.row(2).transpose();
          bias_var0 = u.dot(P.block<3, 3>(9, 9) * u);
        }
        sf_var0 = s.yaw_scale_factor_variance(P);
      }
      weights_.observe_standalone(i, t, s.vehicle_heading(), s.reference_velocity_inW().head<2>().norm(),
                                  s.process_noise(), s.is_wheel(), bias_var0, sf_var0);
    }
    subs.set_weights(weights_.weights());
    return;
  }
  SharedInputs& sh = ctx_.shared;
  take_reference(sh, false);  // every o and its H_mlt at the current state
  const ModuleMask ref = ctx_.reference_modules();
  for (int i = 0; i < subs.size(); ++i) {
    const bool counted = ref[i];
    weights_.observe(i, counted ? reference_point_variance(sh.ref[i], ctx_.filter.covariance(i, scratch)) : 0.0,
                     counted);
  }
  subs.set_weights(weights_.weights());
}

bool PositionConstraintAid::reference_weights(std::array<double, kMaxModules>& k, int& n_ref,
                                              int& n_tied) const {
  // The weights of eq. (8) renormalised over the modules in good health that make the
  // reference (0 for the others: out, on probation, or a steered wheel that follows).
  const int n = ctx_.subs.size();
  const ModuleMask ref = ctx_.reference_modules();
  k.fill(0.0);
  double ksum = 0.0;
  n_ref = n_tied = 0;
  for (int i = 0; i < n; ++i) {
    if (ref[i]) {
      k[i] = ctx_.subs.weight(i);
      ksum += k[i];
      ++n_ref;
    }
    n_tied += ctx_.faults.tied(i);
  }
  if (n_ref == 0 || !(ksum > 0.0)) return false;
  for (int i = 0; i < n; ++i) k[i] /= ksum;
  return true;
}

void PositionConstraintAid::take_reference(SharedInputs& sh, bool level_now) const {
  take_level(ctx_.subs, ctx_.level_shared(), level_now, sh);
  wheelins::take_reference(ctx_.subs, sh);
}

void PositionConstraintAid::measurement(int i, Measurement& m) const {
  SharedInputs sh;
  int n_ref = 0, n_tied = 0;
  reference_weights(sh.k, n_ref, n_tied);
  take_reference(sh, true);
  wheelins::position_measurement(ctx_.subs, sh, ctx_.opt.fusion, i, m);
}

}  // namespace wheelins
