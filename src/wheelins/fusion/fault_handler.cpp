// The fault policy of fault_handler.hpp (docs/faults.md): outages and gaps, re-levelling
// and restarts, saturation, slip, the innovation detector, the heading check.
#include "wheelins/fusion/fault_handler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace wheelins {

namespace {
std::vector<std::string> names_of(const Subsystems& subs) {
  std::vector<std::string> names;
  for (int i = 0; i < subs.size(); ++i) names.push_back(subs[i].module().name);
  return names;
}
}  // namespace

void FaultHandler::finish(double t) {
  monitor_.finish(t);
  for (int i = 0; i < monitor_.size(); ++i) {
    const Evidence& e = evidence_[static_cast<std::size_t>(i)];
    char what[256];
    if (e.rotation >= kEvidenceRotation && e.about_axle < kMinAxleShare * e.rotation) {
      std::snprintf(what, sizeof what,
                    "only %.0f %% of its gyro's rotation (%.0f rad) was about the axle the manifest gives "
                    "(its b-frame x)",
                    100.0 * e.about_axle / e.rotation, e.rotation);
      monitor_.warn(i, t, what,
                    "the wheel spins about another sensor axis: check its axle_axis and mounting_deg (the "
                    "data checks before a run test them); this run's solution is not to be trusted");
    }
    const double rolled = e.forward + e.backward;
    if (rolled >= kEvidenceDistance && e.backward > kMaxBackwardShare * rolled) {
      std::snprintf(what, sizeof what, "its wheel rolled backward for %.0f %% of its %.0f m",
                    100.0 * e.backward / rolled, rolled);
      monitor_.warn(i, t, what,
                    "a vehicle drives forward most of its way: its axle_sign looks reversed (the data "
                    "checks before a run test it); unless it really drove backward, this run's solution "
                    "is not to be trusted");
    }
  }
}

std::unique_ptr<FaultHandler> make_fault_handler(const FaultOptions& options, const Subsystems& subs,
                                                 const FilterBackend& filter, const OutputFusion& output) {
  if (options.enabled) return std::make_unique<FaultPolicy>(options, subs, filter, output);
  return std::make_unique<NoFaultHandling>(names_of(subs), options);
}

FaultPolicy::FaultPolicy(const FaultOptions& options, const Subsystems& subs, const FilterBackend& filter,
                         const OutputFusion& output)
    : FaultHandler(FaultMonitor(names_of(subs), options)),
      opt_(options),
      subs_(subs),
      filter_(filter),
      output_(output),
      rt_(static_cast<std::size_t>(subs.size())) {}

void FaultPolicy::on_start(double t0) {
  for (Runtime& rt : rt_) rt.last_t = t0;
}

bool FaultPolicy::on_sample(int index, const ImuSample& raw, ImuSample& b) {
  Runtime& rt = rt_[index];
  watch_outages(index, raw.t);
  if (monitor_.health(index) == Health::kOut || raw.dt > opt_.max_gap) {
    // The data come back (or jump): this sample's interval is unknown motion. Re-level
    // on the next samples, then restart from the others.
    char what[160];
    std::snprintf(what, sizeof what, "data again after a gap of %.3f s", raw.t - rt.last_t);
    ++monitor_.stats(index).gaps;
    rt.last_t = raw.t;
    begin_realign(index, raw.t, what,
                  "re-levelling on its next samples, then restarting from the others");
    return false;
  }
  rt.last_t = raw.t;
  if (monitor_.health(index) == Health::kRealign) {
    rt.realign.add(b);
    if (rt.realign.duration() + 1e-9 >= opt_.realign_time) restart(index, raw.t);
    return false;
  }
  if (subs_.is_wheel(index) && subs_[index].module().gyro_range > 0.0)
    handle_saturation(index, raw, b);
  return true;
}

void FaultPolicy::screen_speeds(double t, const std::array<WheelVelocityInput, kMaxModules>& wheel,
                                SpeedSelection& sel) {
  // Saturated (a clipped speed is a lower bound: kept as a fallback), or shortly after (its
  // INS is off for a known reason, not a fault: excused from the detector).
  const int n = subs_.size();
  excused_.fill(false);
  for (int i = 0; i < n; ++i) {
    if (!sel.speed_ok[i]) continue;
    if (t < rt_[i].saturated_until) {
      sel.speed_ok[i] = false;
      sel.fallback[i] = true;
    }
    if (t - rt_[i].saturated_until < opt_.retry_after) excused_[i] = true;
  }
  // Rolling with the others (a reversed axle), then agreeing with the other wheels and the
  // wheel's own INS (slip, a lifted wheel).
  check_directions(t, wheel, sel.speed_ok);
  check_wheel_speeds(t, wheel, sel.speed_ok);
  // Every wheel saturated or recovering: the innovations they cause are explained, and no
  // module is blamed for them.
  bool any_excused = false, any_clean = false;
  for (int i = 0; i < n; ++i)
    if (subs_.is_wheel(i) && in_use(i)) (excused_[i] ? any_excused : any_clean) = true;
  degraded_ = any_excused && !any_clean;
}

void FaultPolicy::on_velocity_update(int i, const UpdateReport& rep, double t_now) {
  FaultHandler::on_velocity_update(i, rep, t_now);
  if (excused_[i] || degraded_ || !monitor_.velocity_test(i, rep.test_ratio)) return;
  // The detector fired: isolate the module if the others can go on without it.
  char what[200];
  std::snprintf(what, sizeof what,
                "velocity innovations inconsistent: %d of the last %d test ratios over %.1f",
                opt_.max_failed, opt_.window, opt_.test_ratio);
  // An isolated module navigates alone until its retry: it is already out of everything the
  // others use, and its own innovations say nothing new.
  if (!monitor_.tied(i)) return;
  const int others_ok = monitor_.count_ok() - (monitor_.counts(i) ? 1 : 0);
  if (others_ok >= 1) {
    isolate(i, t_now, what);
  } else if (!rt_[i].detector_fired) {
    rt_[i].detector_fired = true;
    monitor_.note(i, t_now, what,
                  subs_.size() == 1
                      ? "no other module to take over: kept (reported once)"
                      : "no other module in good health to take over: kept (reported once)");
  }
}

void FaultPolicy::watch_outages(int index, double t) {
  for (int j = 0; j < subs_.size(); ++j) {
    if (j == index) continue;
    const Health h = monitor_.health(j);
    if (h == Health::kOut) continue;
    if (t - rt_[j].last_t > opt_.stale_after) {
      char what[96];
      std::snprintf(what, sizeof what, "no data after t=%.3f", rt_[j].last_t);
      monitor_.transition(j, Health::kOut, rt_[j].last_t, what,
                         "left out of the fusion until its data return");
    }
  }
}

bool FaultPolicy::substitute_speed(int wheel_index, double* speed) const {
  // Only another wheel's gyro measures the speed independently (one that has not been
  // saturated for a while: a wheel at the edge of saturation flickers in and out); with
  // every wheel saturated the clipped readings (a lower bound) are all there is.
  const double t = subs_[wheel_index].time();
  double sum = 0.0;
  int n = 0;
  for (int j = 0; j < subs_.size(); ++j)
    if (j != wheel_index && subs_.is_wheel(j) && monitor_.counts(j) &&
        t - rt_[j].saturated_until > kSaturationFree) {
      // Moved to this wheel: v_i = v_j - yaw_rate (y_i - y_j) (v-frame y to the right; the
      // vehicle's forward speeds, a steered wheel's along itself over cos(steering)).
      const auto& wj = subs_.wheel(j);
      sum += wj.longitudinal_speed() - wj.vehicle_yaw_rate() * (subs_[wheel_index].module().p_inV.y() -
                                                                wj.module().p_inV.y());
      ++n;
    }
  if (n) *speed = sum / n / std::cos(subs_.wheel(wheel_index).steering());
  return n > 0;
}

void FaultPolicy::handle_saturation(int index, const ImuSample& raw, ImuSample& b) {
  const double full = opt_.saturation_margin * subs_[index].module().gyro_range * raw.dt;
  if (!(raw.dtheta.cwiseAbs().maxCoeff() >= full)) return;
  Runtime& rt = rt_[index];
  ++monitor_.stats(index).saturated_samples;
  double v = 0.0;
  const bool substituted = substitute_speed(index, &v);
  if (!rt.saturation_reported) {
    rt.saturation_reported = true;
    char what[128];
    std::snprintf(what, sizeof what, "gyro at full scale (%.0f deg/s)",
                  subs_[index].module().gyro_range / kDeg);
    monitor_.note(index, raw.t, what,
                 substituted ? "axle rate from the other wheels' speed; own speed not used"
                             : "no unsaturated wheel: clipped reading kept (speed is a lower "
                               "bound)");
  }
  rt.saturated_until = raw.t + opt_.saturation_hold;
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

void FaultPolicy::check_wheel_speeds(double t, const std::array<WheelVelocityInput, kMaxModules>& own,
                                   std::array<bool, kMaxModules>& speed_ok) {
  // Slip, a lifted or a locked wheel: its speed disagrees with the other wheels' (moved to
  // its place with the yaw rate: v_i = v_j - yaw_rate (y_i - y_j), v-frame y to the
  // right) by more than max(wheel_mismatch, 10 %). The one of a disagreeing set whose
  // speed is furthest from its own INS (in sigma, and beyond speed_gate) is left out.
  // A wheel alone is not checked: against its own INS only, slip cannot be told from INS
  // drift (measured: a 4 s slip with the check on a single Wheel-INS doubled its drift).
  const int n = subs_.size();
  std::array<double, kMaxModules> z{};  // |innovation| / sigma against the own INS
  int n_u = 0;
  double yaw_rate = 0.0;
  for (int i = 0; i < n; ++i) {
    if (!speed_ok[i] || !subs_.is_wheel(i)) continue;
    const auto& w = subs_.wheel(i);
    const WheelVelocityModel m = wheel_velocity_model(own[i]);
    Mat21 scratch;
    const Mat21& P = filter_.covariance(i, scratch);
    const double s_xx = m.H.row(0) * P * m.H.row(0).transpose() + w.velocity_noise()(0, 0);
    z[i] = std::abs(m.innovation().x()) / std::sqrt(s_xx);
    yaw_rate += w.vehicle_yaw_rate();
    ++n_u;
  }
  if (n_u < 2) return;
  yaw_rate /= n_u;
  int suspect = -1;
  for (int i = 0; i < n; ++i) {
    if (!speed_ok[i] || !subs_.is_wheel(i)) continue;
    // The vehicle's forward speeds (a steered wheel's along itself times cos(steering)).
    const double vi = own[i].measured_speed * std::cos(own[i].steering);
    double pred = 0.0;
    for (int j = 0; j < n; ++j)
      if (j != i && speed_ok[j] && subs_.is_wheel(j)) pred += speed_at(i, j, own, yaw_rate);
    pred /= n_u - 1;
    bool disagrees = z[i] > opt_.speed_gate &&
                     std::abs(vi - pred) > std::max(opt_.wheel_mismatch, 0.1 * std::abs(pred));
    if (t - rt_[i].saturated_until < opt_.retry_after) disagrees = false;  // INS recovering
    if (disagrees && (suspect < 0 || z[i] > z[suspect])) suspect = i;
  }
  for (int i = 0; i < n; ++i) {
    if (!speed_ok[i] || !subs_.is_wheel(i)) continue;
    Runtime& rt = rt_[i];
    if (i == suspect) {
      speed_ok[i] = false;
      ++monitor_.stats(i).speed_rejected;
      if (!rt.speed_rejected) {
        char what[200];
        std::snprintf(what, sizeof what,
                      "wheel speed %.3f m/s disagrees with the other wheels' and its INS (%.1f "
                      "sigma): slip or a lifted wheel",
                      own[i].measured_speed, z[i]);
        monitor_.note(i, t, what, "speed not used until it agrees again");
      }
      rt.speed_rejected = true;
    } else if (rt.speed_rejected) {
      monitor_.note(i, t, "wheel speed agrees again", "speed used again");
      rt.speed_rejected = false;
    }
  }
}

double FaultPolicy::speed_at(int i, int j, const std::array<WheelVelocityInput, kMaxModules>& own,
                             double yaw_rate) const {
  return own[j].measured_speed * std::cos(own[j].steering) -
         yaw_rate * (subs_[i].module().p_inV.y() - subs_[j].module().p_inV.y());
}

void FaultPolicy::check_directions(double t, const std::array<WheelVelocityInput, kMaxModules>& own,
                                   std::array<bool, kMaxModules>& speed_ok) {
  // A wheel whose speed has the other sign than the vehicle's motion at its place (the other
  // wheels' speeds moved there with the yaw rate), both above reverse_speed, conflicts with
  // them. The wheel in conflict with the most is outvoted; between equals (two wheels), the
  // body's inertial speed decides once it is above reverse_speed,
  // and without a body the one rolling backward is suspected (a vehicle drives forward most
  // of its way). A suspect's speed is not used; a suspect for reverse_time in a row is isolated for the rest of the run (its axle_sign is reversed: a retry would not
  // mend it). A slip is not mistaken for it: a slipping wheel turns faster the same way.
  const double dt = direction_t_ > -1e300 ? t - direction_t_ : 0.0;
  direction_t_ = t;
  const int n = subs_.size();
  const double vmin = opt_.reverse_speed;
  std::array<bool, kMaxModules> cand{};
  double yaw_rate = 0.0;
  int n_c = 0;
  for (int i = 0; i < n; ++i)
    if (speed_ok[i] && subs_.is_wheel(i) && monitor_.counts(i)) {
      cand[i] = true;
      yaw_rate += subs_.wheel(i).vehicle_yaw_rate();
      ++n_c;
    }
  std::array<int, kMaxModules> conflicts{};
  int most = 0;
  if (n_c >= 2) {
    yaw_rate /= n_c;
    for (int i = 0; i < n; ++i) {
      const double vi = own[i].measured_speed * std::cos(own[i].steering);
      if (!cand[i] || std::abs(vi) < vmin) continue;
      for (int j = 0; j < n; ++j) {
        if (j == i || !cand[j]) continue;
        const double vj = speed_at(i, j, own, yaw_rate);
        if (std::abs(vj) >= vmin && (vi > 0.0) != (vj > 0.0)) ++conflicts[i];
      }
      most = std::max(most, conflicts[i]);
    }
  }
  int n_most = 0;
  for (int i = 0; i < n; ++i) n_most += most > 0 && conflicts[i] == most;
  const bool body = subs_.has_body() && monitor_.counts(subs_.body_index());
  const double v_body = body ? subs_.body().ins_speed() : 0.0;
  for (int i = 0; i < n; ++i) {
    Runtime& rt = rt_[i];
    if (most == 0 || conflicts[i] != most) {
      rt.reverse_time = 0.0;
      continue;
    }
    const double vi = own[i].measured_speed * std::cos(own[i].steering);
    const double vb = v_body - yaw_rate * subs_[i].module().p_inV.y();
    bool suspect = n_most == 1;
    if (!suspect) suspect = std::abs(vb) >= vmin ? (vi > 0.0) != (vb > 0.0) : vi < 0.0;
    rt.reverse_time = suspect ? rt.reverse_time + dt : 0.0;
    if (suspect) speed_ok[i] = false;
    if (rt.reverse_time + 1e-9 < opt_.reverse_time) continue;
    if (monitor_.count_ok() - 1 < 1) continue;  // nobody to take over: reported at the end
    double others = 0.0;
    int n_o = 0;
    for (int j = 0; j < n; ++j)
      if (j != i && cand[j]) {
        others += speed_at(i, j, own, yaw_rate);
        ++n_o;
      }
    char what[256];
    std::snprintf(what, sizeof what,
                  "rolls against the vehicle's motion for %.1f s: its speed %+.2f m/s, the other wheels' "
                  "%+.2f m/s at its place%s",
                  rt.reverse_time, vi, n_o ? others / n_o : 0.0,
                  std::abs(vb) >= vmin && body ? (std::string(", the body's ") +
                                                  (vb > 0.0 ? "forward" : "backward")).c_str()
                                               : "");
    isolate(i, t, what);
    rt.reversed = true;
    monitor_.note(i, t, "its axle_sign looks reversed",
                  "isolated for the rest of the run: check its axle_sign (the data checks before a run test it)");
    // The others' failed tests while it disagreed were its doing.
    for (int j = 0; j < n; ++j)
      if (j != i) monitor_.clear_tests(j);
  }
}

void FaultPolicy::on_velocity_step(double t) {
  for (int i = 0; i < subs_.size(); ++i) {
    Runtime& rt = rt_[i];
    if (monitor_.counts(i) && t - rt.snapshot_t >= kSnapshotInterval) {
      rt.errors_old = rt.have_snapshot ? rt.errors_new : subs_[i].ekf().errors();
      rt.errors_new = subs_[i].ekf().errors();
      rt.snapshot_t = t;
      rt.have_snapshot = true;
    }
    if (rt.saturation_reported && !(t < rt.saturated_until)) {
      rt.saturation_reported = false;
      monitor_.note(i, t, "gyro back in range", "own speed used again");
    }
    const Health h = monitor_.health(i);
    if (h == Health::kProbation && t - monitor_.since(i) >= opt_.probation)
      monitor_.transition(i, Health::kOk, t, "probation passed",
                         "back in the fused solution");
    else if (h == Health::kIsolated && !rt.reversed && t - monitor_.since(i) >= opt_.retry_after)
      begin_realign(i, t, "retry after isolation", "re-levelling, then restarting from the others");
  }
}

void FaultPolicy::isolate(int i, double t, const std::string& what) {
  monitor_.transition(i, Health::kIsolated, t, what,
                     "isolated: out of the fused solution, the mean speed and the constraint");
  monitor_.clear_tests(i);
  rt_[i].revert_errors = true;
  rt_[i].heading_fails = 0;
  // Its heading offset was tracked while the fault went undetected: not to be trusted.
  actions_.forget_heading_offset[static_cast<std::size_t>(i)] = true;
}

void FaultPolicy::on_position_step(double t) {
  // Vehicle heading of every module in good health against the circular mean of the
  // others (the attitude the subsystems share, Section III). With three or more, the
  // one that disagrees most, beyond heading_gate for heading_epochs constraint epochs
  // in a row, is isolated.
  const int n = subs_.size();
  if (monitor_.count_ok() < 3 || degraded_) return;
  std::array<double, kMaxModules> d{};
  int worst = -1;
  for (int i = 0; i < n; ++i) {
    if (!monitor_.counts(i)) continue;
    double s = 0.0, c = 0.0;
    for (int j = 0; j < n; ++j)
      if (j != i && monitor_.counts(j)) {
        s += subs_.weight(j) * std::sin(subs_[j].vehicle_heading());
        c += subs_.weight(j) * std::cos(subs_[j].vehicle_heading());
      }
    d[i] = std::abs(wrap_pi(subs_[i].vehicle_heading() - std::atan2(s, c)));
    if (worst < 0 || d[i] > d[worst]) worst = i;
  }
  for (int i = 0; i < n; ++i) {
    Runtime& rt = rt_[i];
    if (i == worst && d[i] > opt_.heading_gate) ++rt.heading_fails;
    else rt.heading_fails = 0;
    if (rt.heading_fails >= opt_.heading_epochs) {
      char what[160];
      std::snprintf(what, sizeof what, "heading %.1f deg off the others' for %d epochs",
                    d[i] / kDeg, rt.heading_fails);
      isolate(i, t, what);
    }
  }
}

void FaultPolicy::begin_realign(int i, double t, const std::string& what, const std::string& action) {
  rt_[i].realign.clear();
  monitor_.transition(i, Health::kRealign, t, what, action);
}

VehicleFix FaultPolicy::vehicle_fix(int i, double t) const {
  std::array<bool, kMaxModules> use{};
  bool any = false;
  for (int j = 0; j < subs_.size(); ++j) any |= use[j] = j != i && monitor_.counts(j);
  if (!any)
    for (int j = 0; j < subs_.size(); ++j) any |= use[j] = j != i && monitor_.flowing(j);
  VehicleFix fix;
  fix.t = t;
  if (any) {
    const TrajectoryRecord r = output_.fused(use);
    fix.p_OinW = r.p_inN + r.v_inN * (t - r.t);
    fix.v_OinW = r.v_inN;
    // The mean heading of all modules (fused() carries it through the outage) plus this
    // module's own offset from it before the outage: what the others' gyros say it turned
    // by since. Its yaw-rate scale factor's share of its heading is kept, not lost to theirs.
    double offset = 0.0;
    // (An offset this policy decided to forget and is not yet forgotten does not count.)
    const bool own_offset = !actions_.forget_heading_offset[static_cast<std::size_t>(i)] &&
                            output_.heading_offset(i, offset);
    fix.heading = wrap_pi(r.rpy.z() + (own_offset ? offset : 0.0));
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

void FaultPolicy::restart(int i, double t) {
  const VehicleFix fix = vehicle_fix(i, t);
  FaultActions::Restart r;
  r.module = i;
  // The sensor-error estimates learnt while the fault went undetected are not trusted:
  // back to those of 10-20 s before the detection.
  r.revert_errors = rt_[i].revert_errors && rt_[i].have_snapshot;
  r.errors = rt_[i].errors_old;
  r.f_now = rt_[i].realign.mean_f_now();
  r.fix = fix;
  actions_.restart = r;
  rt_[i].revert_errors = false;
  monitor_.clear_tests(i);
  ++monitor_.stats(i).restarts;
  rt_[i].detector_fired = false;
  char what[160];
  std::snprintf(what, sizeof what, "re-initialised (o within %.2f m, heading within %.2f deg)",
                fix.position_std, fix.heading_std / kDeg);
  if (subs_.size() == 1)
    monitor_.transition(i, Health::kOk, t, what, "navigating again");
  else
    monitor_.transition(i, Health::kProbation, t, what,
                       "on probation: tied to the others by the constraint, out of the fused "
                       "solution");
}

}  // namespace wheelins
