#include "wheelins/fusion/navigator.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cstdio>
#include <limits>
#include <cmath>
#include <numeric>
#include <sstream>

namespace wheelins {

Navigator::Navigator(const VehicleSetup& setup, const std::vector<std::string>& modules,
                     const NavigatorOptions& options, Sink sink)
    : opt_(options),
      frame_(setup.origin),
      source_(setup.source),
      static_start_(setup.static_start),
      static_end_(setup.static_end),
      initial_heading_(setup.initial_heading),
      subs_(setup, modules, options),
      filter_(make_filter_backend(subs_, options.fusion.centralized)),
      output_(subs_, *filter_, frame_, opt_, std::move(sink)) {
  opt_.validate();
  static_.resize(subs_.size());
  std::vector<std::string> names;
  for (int i = 0; i < subs_.size(); ++i) names.push_back(subs_[i].module().name);
  faults_ = FaultMonitor(std::move(names), opt_.faults);
  rt_.resize(subs_.size());
}

Navigator::~Navigator() = default;

double Navigator::min_time() const {
  double t = std::numeric_limits<double>::infinity();
  for (int i = 0; i < subsystem_count(); ++i)
    if (in_use(i)) t = std::min(t, subs_[i].time());
  return t;
}

int Navigator::output_driver() const {
  for (int i = 0; i < subsystem_count(); ++i)
    if (in_use(i)) return i;
  return -1;
}

void Navigator::process(int index, const ImuSample& raw) {
  ++stats_.samples;
  Subsystem& s = subs_[index];
  ImuSample b = s.to_body(raw);
  if (!navigating_) {
    if (raw.t <= static_start_) return;
    if (raw.t <= static_end_ + 1e-9) {
      static_[index].add(b);
      return;
    }
    start_navigation(static_end_);
  }
  if (opt_.faults.enabled) {
    Runtime& rt = rt_[index];
    watch_outages(index, raw.t);
    if (faults_.health(index) == Health::kOut || raw.dt > opt_.faults.max_gap) {
      // The data come back (or jump): this sample's interval is unknown motion. Re-level
      // on the next samples, then restart from the others.
      char what[160];
      std::snprintf(what, sizeof what, "data again after a gap of %.3f s", raw.t - rt.last_t);
      ++faults_.stats(index).gaps;
      rt.last_t = raw.t;
      begin_realign(index, raw.t, what,
                    "re-levelling on its next samples, then restarting from the others");
      return;
    }
    rt.last_t = raw.t;
    if (faults_.health(index) == Health::kRealign) {
      rt.realign.add(b);
      if (rt.realign.duration() + 1e-9 >= opt_.faults.realign_time) restart(index, raw.t);
      return;
    }
    if (s.is_wheel() && s.module().gyro_range > 0.0) handle_saturation(index, raw, b);
  }
  s.propagate(b);
  filter_->propagated(index);

  // Updates when every subsystem in use has reached the scheduled time.
  const double t_all = min_time();
  using Clock = std::chrono::steady_clock;
  if (t_all + 1e-9 >= next_velocity_t_) {
    // Every P brought to this epoch before a measurement uses it; outside the timed step,
    // since the time update is not the velocity step's cost (Table 8).
    filter_->flush();
    const auto t0 = Clock::now();
    velocity_updates();
    check_covariances();
    stats_.velocity_step_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++stats_.velocity_steps;
    while (next_velocity_t_ <= t_all + 1e-9) next_velocity_t_ += opt_.wheel.velocity_update_interval;
  }
  if (subs_.size() > 1 && opt_.fusion.position_constraint && t_all + 1e-9 >= next_position_t_) {
    filter_->flush();
    const auto t0 = Clock::now();
    position_update();
    stats_.position_step_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++stats_.position_steps;
    while (next_position_t_ <= t_all + 1e-9)
      next_position_t_ += opt_.fusion.position_update_interval;
  }

  if (index != output_driver()) return;
  ++stats_.epochs;
  stats_.t_end = raw.t;
  // (raw.t > last: when the driving module changes, the new one may share the epoch.)
  if (raw.t + 1e-9 >= next_output_t_ && raw.t > last_output_t_) {
    last_output_t_ = raw.t;
    output_.write(raw.t, vehicle_modules(), in_use_mask());
    ++stats_.records;
    if (opt_.output_interval > 0)
      while (next_output_t_ <= raw.t + 1e-9) next_output_t_ += opt_.output_interval;
  }
}

void Navigator::start_navigation(double t0) {
  for (int i = 0; i < subs_.size(); ++i) {
    if (static_[i].count() < 10) {
      char period[96];
      std::snprintf(period, sizeof period, "[%.3f, %.3f] s", static_start_, static_end_);
      throw InputError("'" + subs_.source(i) + "' (module '" + subs_[i].module().name +
                       "'): only " + std::to_string(static_[i].count()) +
                       " samples in the static period " + period + " of '" + source_ +
                       "': the alignment needs the static period covered by every module's data");
    }
    subs_[i].start(static_[i], initial_heading_, t0);
    rt_[i].last_t = t0;
  }
  filter_->start();
  navigating_ = true;
  stats_.t_start = t0;
  next_output_t_ = t0;
  next_velocity_t_ = t0 + opt_.wheel.velocity_update_interval;
  next_position_t_ = t0 + opt_.fusion.position_update_interval;
}

bool Navigator::level_shared() const {
  // The Body-INS level is shared only while the Body-INS counts (a module on probation or
  // out does not pass its attitude on; the wheels keep the last level they were given).
  return subs_.has_body() && opt_.fusion.share_level && counted(subs_.body_index());
}

void Navigator::share_level() {
  if (!level_shared()) return;
  const Vec3 rpy = subs_.body().vehicle_rpy();
  for (int i = 0; i < subs_.size(); ++i)
    if (subs_.is_wheel(i)) subs_.wheel(i).set_vehicle_level(rpy.x(), rpy.y());
}

std::array<bool, kMaxModules> Navigator::in_use_mask() const {
  std::array<bool, kMaxModules> use{};
  for (int i = 0; i < subs_.size(); ++i) use[i] = in_use(i);
  return use;
}

void Navigator::take_speeds(SharedInputs& sh, bool level_now) const {
  take_level(subs_, level_shared(), level_now, sh);
  take_wheel_inputs(subs_, in_use_mask(), sh);
  take_mean_speed(subs_, speeds_, sh);
}

void Navigator::take_reference(SharedInputs& sh, bool level_now) const {
  take_level(subs_, level_shared(), level_now, sh);
  wheelins::take_reference(subs_, sh);
}

void Navigator::velocity_measurement(int i, Measurement& m) const {
  SharedInputs sh;
  take_speeds(sh, true);
  wheelins::velocity_measurement(subs_, sh, opt_.fusion, i, filter_->joint(), m);
}

bool Navigator::reference_weights(std::array<double, kMaxModules>& k, int& n_ref,
                                  int& n_tied) const {
  // Algorithm 1 over the modules in good health: their weighted mean of o (eq. 9) is the
  // reference, the weights renormalised over them (0 for the others).
  const int n = subsystem_count();
  k.fill(0.0);
  double ksum = 0.0;
  n_ref = n_tied = 0;
  for (int i = 0; i < n; ++i) {
    if (counted(i)) {
      k[i] = subs_.weight(i);
      ksum += k[i];
      ++n_ref;
    }
    n_tied += !opt_.faults.enabled || faults_.tied(i);
  }
  if (n_ref == 0 || !(ksum > 0.0)) return false;
  for (int i = 0; i < n; ++i) k[i] /= ksum;
  return true;
}

void Navigator::position_measurement(int i, Measurement& m) const {
  SharedInputs sh;
  int n_ref = 0, n_tied = 0;
  reference_weights(sh.k, n_ref, n_tied);
  take_reference(sh, true);
  wheelins::position_measurement(subs_, sh, opt_.fusion, i, m);
}

void Navigator::count_velocity_update(int i, const UpdateReport& rep, double t_now) {
  ++stats_.velocity_updates;
  if (!rep.accepted) {
    ++stats_.velocity_rejected;
    ++faults_.stats(i).velocity_rejected;
  }
  stats_.max_velocity_test_ratio = std::max(stats_.max_velocity_test_ratio, rep.test_ratio);
  if (!opt_.faults.enabled || excused_[i] || degraded_ || !faults_.velocity_test(i, rep.test_ratio))
    return;
  // The detector fired: isolate the module if the others can go on without it.
  char what[200];
  std::snprintf(what, sizeof what,
                "velocity innovations inconsistent: %d of the last %d test ratios over %.1f",
                opt_.faults.max_failed, opt_.faults.window, opt_.faults.test_ratio);
  const int others_ok = faults_.count_ok() - (faults_.counts(i) ? 1 : 0);
  if (subsystem_count() > 1 && others_ok >= 1 && faults_.tied(i)) {
    isolate(i, t_now, what);
  } else if (!rt_[i].detector_fired) {
    rt_[i].detector_fired = true;
    faults_.note(i, t_now, what, "no other module to take over: kept (reported once)");
  }
}

void Navigator::velocity_updates() {
  const bool handle = opt_.faults.enabled;
  const double t_now = min_time();
  if (handle) fault_housekeeping(t_now);
  // Shared information (Section III): vehicle level from the Body-INS, wheel speed.
  share_level();
  // Which wheel speeds can be used: not saturated, and (fault handling on) agreeing with
  // the wheel's own INS to within speed_gate sigma of the predicted forward velocity.
  const int n_sub = subs_.size();
  SharedInputs& sh = shared_;
  take_level(subs_, level_shared(), false, sh);
  take_wheel_inputs(subs_, in_use_mask(), sh);
  SpeedSelection& sel = speeds_;
  sel = SpeedSelection();
  std::array<bool, kMaxModules> saturated{};
  excused_.fill(false);
  for (int i = 0; i < n_sub; ++i) {
    if (!subs_.is_wheel(i) || !in_use(i)) continue;
    if (handle && t_now < rt_[i].saturated_until) saturated[i] = true;
    sel.speed_ok[i] = !saturated[i];
    // Saturated, or shortly after: its INS is off for a known reason, not a fault.
    if (handle && t_now - rt_[i].saturated_until < opt_.faults.retry_after) excused_[i] = true;
  }
  if (handle) check_wheel_speeds(t_now, sh.wheel, sel.speed_ok);
  for (int i = 0; i < n_sub; ++i) {
    if (!subs_.is_wheel(i) || !in_use(i)) continue;
    if (sel.speed_ok[i] && counted(i)) {
      sel.in_mean[i] = true;
      ++sel.n_mean;
    }
  }
  // Every wheel saturated: their clipped speeds (lower bounds) are better than none, and
  // the innovations they cause are explained: no module is blamed for them.
  {
    bool any_excused = false, any_clean = false;
    for (int i = 0; i < n_sub; ++i)
      if (subs_.is_wheel(i) && in_use(i)) (excused_[i] ? any_excused : any_clean) = true;
    degraded_ = any_excused && !any_clean;
  }
  if (sel.n_mean == 0)
    for (int i = 0; i < n_sub; ++i)
      if (saturated[i] && counted(i)) {
        sel.speed_ok[i] = sel.in_mean[i] = true;
        ++sel.n_mean;
      }
  take_mean_speed(subs_, sel, sh);
  // The distributed filter's updates all use the epoch's shared quantities; the centralized
  // filter's sequential updates each see the state the previous one left (the joint
  // correction moves every IMU's errors), with the epoch's speed selection.
  const bool joint = filter_->joint();
  for (int i = 0; i < n_sub; ++i) {
    if (!in_use(i)) continue;
    if (joint) {
      share_level();
      take_speeds(sh, false);
    }
    wheelins::velocity_measurement(subs_, sh, opt_.fusion, i, joint, meas_);
    count_velocity_update(i, filter_->fuse(meas_), t_now);
  }
}

Mat21 Navigator::covariance(int i) const {
  Mat21 scratch;
  return filter_->covariance(i, scratch);
}

void Navigator::position_update() {
  // Algorithm 1 over the modules in good health: their weighted mean of o (eq. 8) is the
  // reference; modules on probation are tied to it without moving it.
  const int n = subs_.size();
  SharedInputs& sh = shared_;
  int n_ref = 0, n_tied = 0;
  const bool have_ref = reference_weights(sh.k, n_ref, n_tied);
  if (opt_.faults.enabled) check_headings(min_time());
  if (!have_ref || n_tied < 2) return;
  auto record = [&](const UpdateReport& rep) {
    ++stats_.position_updates;
    if (!rep.accepted) ++stats_.position_rejected;
    stats_.max_position_test_ratio = std::max(stats_.max_position_test_ratio, rep.test_ratio);
  };
  auto receives = [&](int i) {
    // A lone reference module is not constrained by itself.
    return (!opt_.faults.enabled || faults_.tied(i)) && !(n_ref == 1 && sh.k[i] > 0.0);
  };
  // Distributed: every subsystem's o at the level the Wheel-INSs were last given; centralized:
  // each update re-evaluated at the state the previous one left.
  const bool joint = filter_->joint();
  if (!joint) take_reference(sh, false);
  for (int i = 0; i < n; ++i) {
    if (!receives(i)) continue;
    if (joint) {
      share_level();
      take_reference(sh, false);
    }
    wheelins::position_measurement(subs_, sh, opt_.fusion, i, meas_);
    record(filter_->fuse(meas_));
  }
}

std::array<bool, Navigator::kMaxModules> Navigator::vehicle_modules() const {
  std::array<bool, kMaxModules> use{};
  bool any = false;
  for (int i = 0; i < subsystem_count(); ++i) any |= use[i] = counted(i);
  if (!any)
    for (int i = 0; i < subsystem_count(); ++i) use[i] = in_use(i);
  return use;
}

TrajectoryRecord Navigator::vehicle_record() const { return output_.fused(vehicle_modules()); }

// ------------------------------------------------------------------ fault handling

void Navigator::watch_outages(int index, double t) {
  for (int j = 0; j < subsystem_count(); ++j) {
    if (j == index) continue;
    const Health h = faults_.health(j);
    if (h == Health::kOut) continue;
    if (t - rt_[j].last_t > opt_.faults.stale_after) {
      char what[96];
      std::snprintf(what, sizeof what, "no data after t=%.3f", rt_[j].last_t);
      faults_.transition(j, Health::kOut, rt_[j].last_t, what,
                         "left out of the fusion until its data return");
    }
  }
}

bool Navigator::substitute_speed(int wheel_index, double* speed) const {
  // Only another wheel's gyro measures the speed independently (one that has not been
  // saturated for a while: a wheel at the edge of saturation flickers in and out); with
  // every wheel saturated the clipped readings (a lower bound) are all there is.
  const double t = subs_[wheel_index].time();
  double sum = 0.0;
  int n = 0;
  for (int j = 0; j < subsystem_count(); ++j)
    if (j != wheel_index && subs_.is_wheel(j) && counted(j) &&
        t - rt_[j].saturated_until > kSaturationFree) {
      // Moved to this wheel: v_i = v_j - yaw_rate (y_i - y_j) (v-frame y to the right).
      const auto& wj = subs_.wheel(j);
      sum += wj.wheel_speed() -
             wj.yaw_rate() * (subs_[wheel_index].module().p_inV.y() - wj.module().p_inV.y());
      ++n;
    }
  if (n) *speed = sum / n;
  return n > 0;
}

void Navigator::handle_saturation(int index, const ImuSample& raw, ImuSample& b) {
  const double full = opt_.faults.saturation_margin * subs_[index].module().gyro_range * raw.dt;
  if (!(raw.dtheta.cwiseAbs().maxCoeff() >= full)) return;
  Runtime& rt = rt_[index];
  ++faults_.stats(index).saturated_samples;
  double v = 0.0;
  const bool substituted = substitute_speed(index, &v);
  if (!rt.saturation_reported) {
    rt.saturation_reported = true;
    char what[128];
    std::snprintf(what, sizeof what, "gyro at full scale (%.0f deg/s)",
                  subs_[index].module().gyro_range / kDeg);
    faults_.note(index, raw.t, what,
                 substituted ? "axle rate from the other wheels' speed; own speed not used"
                             : "no unsaturated wheel: clipped reading kept (speed is a lower "
                               "bound)");
  }
  rt.saturated_until = raw.t + opt_.faults.saturation_hold;
  if (!substituted) return;
  // The axle rate the wheel must have at that speed replaces the clipped reading (the
  // estimated bias is added back, as the filter removes it). The edited sample is what
  // propagate() gets, so the speed window (raw rates, compensated with the current
  // estimates) holds the substituted rate too. (Putting the scale factor back as well,
  // (1 + s_g,x), made the saturation test worse: 3.3 % drift instead of 1.2 %.)
  // The reading says the wheel turns at least at full scale.
  const auto& w = subs_.wheel(index);
  const double floor = subs_[index].module().gyro_range * subs_[index].module().wheel_radius;
  const double v_sub = std::abs(v) >= floor ? v : std::copysign(floor, v);
  b.dtheta.x() = (w.omega_x_at_speed(v_sub) + w.ekf().errors().bg.x()) * b.dt;
}

void Navigator::check_wheel_speeds(double t, const std::array<WheelVelocityInput, kMaxModules>& own,
                                   std::array<bool, kMaxModules>& speed_ok) {
  // Slip, a lifted or a locked wheel: its speed disagrees with the other wheels' (moved to
  // its place with the yaw rate: v_i = v_j - yaw_rate (y_i - y_j), v-frame y to the
  // right) by more than max(wheel_mismatch, 10 %). The one of a disagreeing set whose
  // speed is furthest from its own INS (in sigma, and beyond speed_gate) is left out.
  // A wheel alone is not checked: against its own INS only, slip cannot be told from INS
  // drift (measured: a 4 s slip with the check on a single Wheel-INS doubled its drift).
  const int n = subsystem_count();
  std::array<double, kMaxModules> z{};  // |innovation| / sigma against the own INS
  int n_u = 0;
  double yaw_rate = 0.0;
  for (int i = 0; i < n; ++i) {
    if (!speed_ok[i] || !subs_.is_wheel(i)) continue;
    const auto& w = subs_.wheel(i);
    const WheelVelocityModel m = wheel_velocity_model(own[i]);
    const Mat21 P = covariance(i);
    const double s_xx = m.H.row(0) * P * m.H.row(0).transpose() + w.velocity_noise()(0, 0);
    z[i] = std::abs(m.innovation().x()) / std::sqrt(s_xx);
    yaw_rate += w.yaw_rate();
    ++n_u;
  }
  if (n_u < 2) return;
  yaw_rate /= n_u;
  int suspect = -1;
  for (int i = 0; i < n; ++i) {
    if (!speed_ok[i] || !subs_.is_wheel(i)) continue;
    const double vi = own[i].measured_speed, yi = subs_[i].module().p_inV.y();
    double pred = 0.0;
    for (int j = 0; j < n; ++j)
      if (j != i && speed_ok[j] && subs_.is_wheel(j))
        pred += own[j].measured_speed - yaw_rate * (yi - subs_[j].module().p_inV.y());
    pred /= n_u - 1;
    bool disagrees = z[i] > opt_.faults.speed_gate &&
                     std::abs(vi - pred) > std::max(opt_.faults.wheel_mismatch, 0.1 * std::abs(pred));
    if (t - rt_[i].saturated_until < opt_.faults.retry_after) disagrees = false;  // INS recovering
    if (disagrees && (suspect < 0 || z[i] > z[suspect])) suspect = i;
  }
  for (int i = 0; i < n; ++i) {
    if (!speed_ok[i] || !subs_.is_wheel(i)) continue;
    Runtime& rt = rt_[i];
    if (i == suspect) {
      speed_ok[i] = false;
      ++faults_.stats(i).speed_rejected;
      if (!rt.speed_rejected) {
        char what[200];
        std::snprintf(what, sizeof what,
                      "wheel speed %.3f m/s disagrees with the other wheels' and its INS (%.1f "
                      "sigma): slip or a lifted wheel",
                      own[i].measured_speed, z[i]);
        faults_.note(i, t, what, "speed not used until it agrees again");
      }
      rt.speed_rejected = true;
    } else if (rt.speed_rejected) {
      faults_.note(i, t, "wheel speed agrees again", "speed used again");
      rt.speed_rejected = false;
    }
  }
}

void Navigator::fault_housekeeping(double t) {
  for (int i = 0; i < subsystem_count(); ++i) {
    Runtime& rt = rt_[i];
    if (faults_.counts(i) && t - rt.snapshot_t >= kSnapshotInterval) {
      rt.errors_old = rt.have_snapshot ? rt.errors_new : subs_[i].ekf().errors();
      rt.errors_new = subs_[i].ekf().errors();
      rt.snapshot_t = t;
      rt.have_snapshot = true;
    }
    if (rt.saturation_reported && !(t < rt.saturated_until)) {
      rt.saturation_reported = false;
      faults_.note(i, t, "gyro back in range", "own speed used again");
    }
    const Health h = faults_.health(i);
    if (h == Health::kProbation && t - faults_.since(i) >= opt_.faults.probation)
      faults_.transition(i, Health::kOk, t, "probation passed",
                         "back in the fused solution");
    else if (h == Health::kIsolated && t - faults_.since(i) >= opt_.faults.retry_after)
      begin_realign(i, t, "retry after isolation", "re-levelling, then restarting from the others");
  }
}

void Navigator::isolate(int i, double t, const std::string& what) {
  faults_.transition(i, Health::kIsolated, t, what,
                     "isolated: out of the fused solution, the mean speed and the constraint");
  faults_.clear_tests(i);
  rt_[i].revert_errors = true;
  rt_[i].heading_fails = 0;
}

void Navigator::check_headings(double t) {
  // Vehicle heading of every module in good health against the circular mean of the
  // others (the attitude the subsystems share, Section III). With three or more, the
  // one that disagrees most, beyond heading_gate for heading_epochs constraint epochs
  // in a row, is isolated.
  const int n = subsystem_count();
  if (faults_.count_ok() < 3 || degraded_) return;
  std::array<double, kMaxModules> d{};
  int worst = -1;
  for (int i = 0; i < n; ++i) {
    if (!faults_.counts(i)) continue;
    double s = 0.0, c = 0.0;
    for (int j = 0; j < n; ++j)
      if (j != i && faults_.counts(j)) {
        s += subs_.weight(j) * std::sin(subs_[j].vehicle_heading());
        c += subs_.weight(j) * std::cos(subs_[j].vehicle_heading());
      }
    d[i] = std::abs(wrap_pi(subs_[i].vehicle_heading() - std::atan2(s, c)));
    if (worst < 0 || d[i] > d[worst]) worst = i;
  }
  for (int i = 0; i < n; ++i) {
    Runtime& rt = rt_[i];
    if (i == worst && d[i] > opt_.faults.heading_gate) ++rt.heading_fails;
    else rt.heading_fails = 0;
    if (rt.heading_fails >= opt_.faults.heading_epochs) {
      char what[160];
      std::snprintf(what, sizeof what, "heading %.1f deg off the others' for %d epochs",
                    d[i] / kDeg, rt.heading_fails);
      isolate(i, t, what);
    }
  }
}

void Navigator::begin_realign(int i, double t, const std::string& what, const std::string& action) {
  rt_[i].realign.clear();
  faults_.transition(i, Health::kRealign, t, what, action);
}

VehicleFix Navigator::vehicle_fix(int i, double t) const {
  std::array<bool, kMaxModules> use{};
  bool any = false;
  for (int j = 0; j < subsystem_count(); ++j) any |= use[j] = j != i && counted(j);
  if (!any)
    for (int j = 0; j < subsystem_count(); ++j) any |= use[j] = j != i && in_use(j);
  VehicleFix fix;
  fix.t = t;
  if (any) {
    const TrajectoryRecord r = output_.fused(use);
    fix.p_OinW = r.p_inN + r.v_inN * (t - r.t);
    fix.v_OinW = r.v_inN;
    fix.heading = r.rpy.z();
    fix.position_std = r.p_std.norm() + 0.05;
    fix.heading_std = r.rpy_std.z() + 0.5 * kDeg;
    return fix;
  }
  // Alone: its own solution before the gap, extrapolated at constant velocity; the
  // uncertainty grows with the distance driven blind.
  const TrajectoryRecord r = output_.record(i);
  const double blind = (t - r.t) * r.v_inN.norm();
  fix.p_OinW = r.p_inN + r.v_inN * (t - r.t);
  fix.v_OinW = r.v_inN;
  fix.heading = r.rpy.z();
  fix.position_std = r.p_std.norm() + 0.1 + 0.3 * blind;
  fix.heading_std = r.rpy_std.z() + 2.0 * kDeg;
  return fix;
}

void Navigator::restart(int i, double t) {
  const VehicleFix fix = vehicle_fix(i, t);
  if (rt_[i].revert_errors && rt_[i].have_snapshot) {
    // The sensor-error estimates learnt while the fault went undetected are not trusted:
    // back to those of 10-20 s before the detection.
    subs_[i].ekf().set_errors(rt_[i].errors_old);
  }
  rt_[i].revert_errors = false;
  subs_[i].restart(rt_[i].realign.mean_f_now(), fix);
  filter_->restarted(i);
  faults_.clear_tests(i);
  ++faults_.stats(i).restarts;
  rt_[i].detector_fired = false;
  char what[160];
  std::snprintf(what, sizeof what, "re-initialised (o within %.2f m, heading within %.2f deg)",
                fix.position_std, fix.heading_std / kDeg);
  if (subsystem_count() == 1)
    faults_.transition(i, Health::kOk, t, what, "navigating again");
  else
    faults_.transition(i, Health::kProbation, t, what,
                       "on probation: tied to the others by the constraint, out of the fused "
                       "solution");
}

void Navigator::check_covariances() {
  for (int i = 0; i < subsystem_count(); ++i) {
    if (!in_use(i)) continue;
    const Mat21 P = covariance(i);
    ++stats_.covariance_checks;
    const double scale = P.cwiseAbs().maxCoeff();
    if (scale > 0.0)
      stats_.max_covariance_asymmetry = std::max(
          stats_.max_covariance_asymmetry, (P - P.transpose()).cwiseAbs().maxCoeff() / scale);
    const Eigen::LLT<Mat21> llt(P);
    if (llt.info() != Eigen::Success || !(scale > 0.0)) ++stats_.covariance_not_pd;
  }
}

void Navigator::finish() { faults_.finish(stats_.t_end); }

}  // namespace wheelins
