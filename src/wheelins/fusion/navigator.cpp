// The navigator of navigator.hpp: alignment, the per-sample flow of process(), the
// velocity and position-constraint steps, and the bookkeeping (stats, covariance health).
#include "wheelins/fusion/navigator.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

namespace wheelins {

namespace {
std::vector<double> configured_weights(const Subsystems& subs) {
  std::vector<double> w(subs.size());
  for (int i = 0; i < subs.size(); ++i) w[i] = subs.weight(i);
  return w;
}
}  // namespace

namespace {
/// The options with what depends on the selection decided (NavigatorOptions::resolved).
NavigatorOptions resolve(const NavigatorOptions& o, const VehicleSetup& setup,
                         const std::vector<std::string>& modules) {
  bool body = false;
  for (const auto& name : modules)
    if (const ImuModule* m = setup.find(name)) body = body || m->kind == ModuleKind::kBody;
  return o.resolved(static_cast<int>(modules.size()), body);
}
}  // namespace

Navigator::Navigator(const VehicleSetup& setup, const std::vector<std::string>& modules,
                     const NavigatorOptions& options, Sink sink)
    : opt_(resolve(options, setup, modules)),
      frame_(setup.origin),
      source_(setup.source),
      static_start_(setup.static_start),
      static_end_(setup.static_end),
      initial_heading_(setup.initial_heading),
      subs_(setup, modules, opt_),
      filter_(make_filter_backend(subs_, options.fusion.centralized)),
      output_(subs_, *filter_, frame_, opt_, std::move(sink)),
      faults_(make_fault_handler(opt_.faults, subs_, *filter_, output_)),
      noise_(opt_.noise, subs_, opt_.wheel.velocity_update_interval),
      weights_(opt_.fusion, configured_weights(subs_)) {
  opt_.validate();
  static_.resize(subs_.size());
  standstill_.configure(opt_.standstill);
}

Navigator::~Navigator() = default;

void Navigator::process(int index, const ImuSample& raw) {
  ++stats_.samples;
  Subsystem& s = subs_[index];
  // The vehicle's motion over a stretch with no data from any module is unknown: bridged
  // (extrapolated) up to max_outage, an error beyond it (docs/faults.md, "Outages").
  if (last_sample_t_ >= static_start_ && raw.t - last_sample_t_ > opt_.faults.max_outage) {
    char what[256];
    std::snprintf(what, sizeof what,
                  "no data from any module between t = %.6f s and t = %.6f s (a gap of %.6g s, longer "
                  "than faults.max_outage_s = %g s): the vehicle's motion across it is unknown, so the "
                  "navigation stops here",
                  last_sample_t_, raw.t, raw.t - last_sample_t_, opt_.faults.max_outage);
    throw OutageError("'" + subs_.source(index) + "' (module '" + s.module().name + "'): " + what, index,
                      last_sample_t_, raw.t);
  }
  if (raw.t > last_sample_t_) last_sample_t_ = raw.t;
  ImuSample b = s.to_body(raw);
  if (!navigating_) {
    if (raw.t <= static_start_) return;
    if (raw.t <= static_end_ + 1e-9) {
      static_[index].add(b);
      return;
    }
    start_navigation(static_end_);
  }
  if (!faults_->on_sample(index, raw, b)) return;
  // A steered wheel's start takes the vehicle's heading from an IMU that does not steer.
  if (s.is_wheel() && !subs_.wheel(index).steering_settled())
    subs_.wheel(index).set_reference_heading(unsteered_heading(index));
  // Mechanization, and the covariance time update when due (the filter's).
  s.propagate(b);
  filter_->propagated(index);
  standstill_.add(index, b, s.ekf().errors());
  if (s.is_wheel()) faults_->tally_rotation(index, b);

  // Updates when every subsystem in use has reached the scheduled time.
  const double t_all = min_time();
  using Clock = std::chrono::steady_clock;
  if (t_all + 1e-9 >= next_velocity_t_) {
    // Every P brought to this epoch before a measurement uses it; outside the timed step,
    // since the time update is not the velocity step's cost (Table 8).
    filter_->flush();
    const auto t0 = Clock::now();
    velocity_step();
    check_covariances();
    stats_.velocity_step_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++stats_.velocity_steps;
    while (next_velocity_t_ <= t_all + 1e-9) next_velocity_t_ += opt_.wheel.velocity_update_interval;
  }
  if (subs_.size() > 1 && opt_.fusion.position_constraint && t_all + 1e-9 >= next_position_t_) {
    filter_->flush();
    const auto t0 = Clock::now();
    position_step();
    stats_.position_step_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    ++stats_.position_steps;
    while (next_position_t_ <= t_all + 1e-9)
      next_position_t_ += opt_.fusion.position_update_interval;
  }

  // Output at the epochs of the first module in use.
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
    if (static_[i].count() < kMinStaticSamples) {
      char period[96];
      std::snprintf(period, sizeof period, "[%.3f, %.3f] s", static_start_, static_end_);
      throw InputError("'" + subs_.source(i) + "' (module '" + subs_[i].module().name +
                       "'): only " + std::to_string(static_[i].count()) +
                       " samples in the static period " + period + " of '" + source_ +
                       "': the alignment needs the static period covered by every module's data");
    }
    subs_[i].start(static_[i], initial_heading_, t0);
    noise_.on_start(i, static_[i], t0);
  }
  filter_->start();
  faults_->on_start(t0);
  navigating_ = true;
  stats_.t_start = t0;
  next_output_t_ = t0;
  next_velocity_t_ = t0 + opt_.wheel.velocity_update_interval;
  next_position_t_ = t0 + opt_.fusion.position_update_interval;
}

// ------------------------------------------------------------------ velocity updates

void Navigator::velocity_step() {
  const double t = min_time();
  faults_->on_velocity_step(t);
  // Shared information (Section III): the vehicle level from the Body-INS, the wheel speed.
  share_level();
  if (standstill_.evaluate(vehicle_modules(), subs_.size(), t)) {
    zero_motion_step();
    return;
  }
  SharedInputs& sh = shared_;
  take_level(subs_, level_shared(), false, sh);
  take_wheel_inputs(subs_, in_use_mask(), sh);
  for (int i = 0; i < subs_.size(); ++i)
    if (subs_.is_wheel(i) && faults_->in_use(i))
      faults_->tally_speed(i, sh.wheel[i].measured_speed, opt_.wheel.velocity_update_interval);
  select_speeds(t);
  take_mean_speed(subs_, speeds_, sh);
  // The distributed filter's updates all use the step's shared quantities; the centralized
  // filter's sequential updates each see the state the previous one left (a joint correction
  // moves every IMU's errors), with the step's speed selection.
  const bool joint = filter_->joint();
  for (int i = 0; i < subs_.size(); ++i) {
    if (!faults_->in_use(i)) continue;
    if (joint) {
      share_level();
      take_speeds(sh, false);
    }
    wheelins::velocity_measurement(subs_, sh, opt_.fusion, i, joint, meas_);
    noise_.prepare_velocity(i, meas_);
    const Vec3 bias_before = subs_[i].ekf().errors().bg;
    const UpdateReport rep = filter_->fuse(meas_);
    noise_.after_velocity(i, meas_, rep, bias_before, t);
    count_velocity_update(i, rep, t);
  }
}

void Navigator::zero_motion_step() {
  // Not tested by the fault detector: a standing vehicle's innovations are not evidence
  // against a module (and its wheel speeds not against the others').
  const StandstillOptions& o = opt_.standstill;
  for (int i = 0; i < subs_.size(); ++i) {
    if (!faults_->in_use(i) || !standstill_.quiet(i)) continue;
    wheelins::zero_velocity_measurement(subs_, i, o.velocity_std, meas_);
    filter_->fuse(meas_);
    wheelins::zero_rate_measurement(subs_, i, standstill_.mean_raw_rate(i), standstill_.window(i), o.rate_std,
                                    meas_);
    filter_->fuse(meas_);
    stats_.zero_motion_updates += 2;
  }
  ++stats_.standstill_steps;
}

void Navigator::select_speeds(double t) {
  // Every wheel in use; the fault handling leaves out the unusable ones (saturated, slipping).
  SpeedSelection& sel = speeds_;
  sel = SpeedSelection();
  for (int i = 0; i < subs_.size(); ++i) sel.speed_ok[i] = subs_.is_wheel(i) && faults_->in_use(i);
  faults_->screen_speeds(t, shared_.wheel, sel);
  // The mean is over the usable speeds of the wheels that count; with none, the clipped
  // speeds of saturated wheels (lower bounds) are better than none.
  for (int i = 0; i < subs_.size(); ++i)
    if (sel.speed_ok[i] && faults_->counted(i)) {
      sel.in_mean[i] = true;
      ++sel.n_mean;
    }
  if (sel.n_mean == 0)
    for (int i = 0; i < subs_.size(); ++i)
      if (sel.fallback[i] && faults_->counted(i)) {
        sel.speed_ok[i] = sel.in_mean[i] = true;
        ++sel.n_mean;
      }
  // Unsteered wheels measure the vehicle's forward speed directly; a steered wheel's depends
  // on its estimated steering: it counts in the mean only when no unsteered wheel does.
  bool unsteered = false;
  for (int i = 0; i < subs_.size(); ++i)
    unsteered = unsteered || (sel.in_mean[i] && !subs_.wheel(i).steered());
  if (unsteered)
    for (int i = 0; i < subs_.size(); ++i)
      if (sel.in_mean[i] && subs_.wheel(i).steered()) {
        sel.in_mean[i] = false;
        --sel.n_mean;
      }
}

void Navigator::count_velocity_update(int i, const UpdateReport& rep, double t) {
  ++stats_.velocity_updates;
  if (!rep.accepted) ++stats_.velocity_rejected;
  stats_.max_velocity_test_ratio = std::max(stats_.max_velocity_test_ratio, rep.test_ratio);
  faults_->on_velocity_update(i, rep, t);
}

double Navigator::unsteered_heading(int except) const {
  // A counted subsystem that does not steer, a body first (its heading is its own attitude's).
  int best = -1;
  for (int j = 0; j < subs_.size(); ++j) {
    if (j == except || !faults_->counted(j) || !subs_[j].ekf().initialized()) continue;
    if (subs_.is_wheel(j) && subs_.wheel(j).steered()) continue;
    if (best < 0 || !subs_.is_wheel(j)) best = j;
    if (!subs_.is_wheel(j)) break;
  }
  return best < 0 ? SteeringObserver::kNoHeading : subs_[best].vehicle_heading();
}

bool Navigator::level_shared() const {
  // The Body-INS level is shared only while the Body-INS counts (a module on probation or
  // out does not pass its attitude on; the wheels keep the last level they were given).
  return subs_.has_body() && opt_.fusion.share_level && faults_->counted(subs_.body_index());
}

void Navigator::share_level() {
  if (!level_shared()) return;
  const Vec3 rpy = subs_.body().vehicle_rpy();
  for (int i = 0; i < subs_.size(); ++i)
    if (subs_.is_wheel(i)) subs_.wheel(i).set_vehicle_level(rpy.x(), rpy.y());
}

void Navigator::take_speeds(SharedInputs& sh, bool level_now) const {
  take_level(subs_, level_shared(), level_now, sh);
  take_wheel_inputs(subs_, in_use_mask(), sh);
  take_mean_speed(subs_, speeds_, sh);
}

void Navigator::velocity_measurement(int i, Measurement& m) const {
  SharedInputs sh;
  take_speeds(sh, true);
  wheelins::velocity_measurement(subs_, sh, opt_.fusion, i, filter_->joint(), m);
}

// ------------------------------------------------------------------ position constraint

void Navigator::position_step() {
  // Algorithm 1 over the modules in good health: their weighted mean of o (eq. 8) is the
  // reference; modules on probation are tied to it without moving it.
  SharedInputs& sh = shared_;
  int n_ref = 0, n_tied = 0;
  if (weights_.from_covariance() || weights_.from_standalone()) update_weights();
  const bool have_ref = reference_weights(sh.k, n_ref, n_tied);
  faults_->on_position_step(min_time());
  if (have_ref) weights_.record(min_time(), sh.k);
  if (!have_ref || n_tied < 2) return;
  auto record = [&](const UpdateReport& rep) {
    ++stats_.position_updates;
    if (!rep.accepted) ++stats_.position_rejected;
    stats_.max_position_test_ratio = std::max(stats_.max_position_test_ratio, rep.test_ratio);
  };
  // Distributed: every subsystem's o at the level the Wheel-INSs were last given; centralized:
  // each update re-evaluated at the state the previous one left.
  const bool joint = filter_->joint();
  if (!joint) take_reference(sh, false);
  for (int i = 0; i < subs_.size(); ++i) {
    // A lone reference module is not constrained by itself.
    if (!faults_->tied(i) || (n_ref == 1 && sh.k[i] > 0.0)) continue;
    if (joint) {
      share_level();
      take_reference(sh, false);
    }
    wheelins::position_measurement(subs_, sh, opt_.fusion, i, meas_);
    const UpdateReport rep = filter_->fuse(meas_);
    noise_.after_position(i, rep);
    record(rep);
  }
}

void Navigator::update_weights() {
  SharedInputs& sh = shared_;
  if (weights_.from_standalone()) {
    Mat21 scratch;
    const double t = min_time();
    for (int i = 0; i < subs_.size(); ++i) {
      const Subsystem& s = subs_[i];
      double bias_var0 = 0.0;
      if (!s.is_wheel() && !weights_.drift(i).started) {
        // The body's vertical gyro bias variance as its filter holds it now (after the
        // alignment): u^T P_bg u with u the vertical in the b-frame.
        const Vec3 u = s.reference_point_input().C_BtoW.row(2).transpose();
        bias_var0 = u.dot(filter_->covariance(i, scratch).block<3, 3>(9, 9) * u);
      }
      weights_.observe_standalone(i, t, s.reference_velocity_inW().head<2>().norm(), s.process_noise(),
                                  s.is_wheel(), bias_var0);
    }
    subs_.set_weights(weights_.weights());
    return;
  }
  take_reference(sh, false);  // every o and its H_mlt at the current state
  Mat21 scratch;
  for (int i = 0; i < subs_.size(); ++i) {
    const bool counted = faults_->counted(i);
    weights_.observe(i, counted ? reference_point_variance(sh.ref[i], filter_->covariance(i, scratch)) : 0.0,
                     counted);
  }
  subs_.set_weights(weights_.weights());
}

bool Navigator::reference_weights(std::array<double, kMaxModules>& k, int& n_ref,
                                  int& n_tied) const {
  // The weights of eq. (8) renormalised over the modules in good health (0 for the others).
  const int n = subs_.size();
  k.fill(0.0);
  double ksum = 0.0;
  n_ref = n_tied = 0;
  for (int i = 0; i < n; ++i) {
    if (faults_->counted(i)) {
      k[i] = subs_.weight(i);
      ksum += k[i];
      ++n_ref;
    }
    n_tied += faults_->tied(i);
  }
  if (n_ref == 0 || !(ksum > 0.0)) return false;
  for (int i = 0; i < n; ++i) k[i] /= ksum;
  return true;
}

void Navigator::take_reference(SharedInputs& sh, bool level_now) const {
  take_level(subs_, level_shared(), level_now, sh);
  wheelins::take_reference(subs_, sh);
}

void Navigator::position_measurement(int i, Measurement& m) const {
  SharedInputs sh;
  int n_ref = 0, n_tied = 0;
  reference_weights(sh.k, n_ref, n_tied);
  take_reference(sh, true);
  wheelins::position_measurement(subs_, sh, opt_.fusion, i, m);
}

// ------------------------------------------------------------------ bookkeeping

double Navigator::min_time() const {
  double t = std::numeric_limits<double>::infinity();
  for (int i = 0; i < subs_.size(); ++i)
    if (faults_->in_use(i)) t = std::min(t, subs_[i].time());
  return t;
}

int Navigator::output_driver() const {
  for (int i = 0; i < subs_.size(); ++i)
    if (faults_->in_use(i)) return i;
  return -1;
}

Navigator::Use Navigator::in_use_mask() const {
  Use use{};
  for (int i = 0; i < subs_.size(); ++i) use[i] = faults_->in_use(i);
  return use;
}

Navigator::Use Navigator::vehicle_modules() const {
  Use use{};
  bool any = false;
  for (int i = 0; i < subs_.size(); ++i) any |= use[i] = faults_->counted(i);
  if (!any) use = in_use_mask();
  return use;
}

TrajectoryRecord Navigator::vehicle_record() const { return output_.fused(vehicle_modules()); }

void Navigator::check_covariances() {
  Mat21 scratch;
  for (int i = 0; i < subs_.size(); ++i) {
    if (!faults_->in_use(i)) continue;
    const Mat21& P = filter_->covariance(i, scratch);
    ++stats_.covariance_checks;
    const double scale = P.cwiseAbs().maxCoeff();
    if (scale > 0.0)
      stats_.max_covariance_asymmetry = std::max(
          stats_.max_covariance_asymmetry, (P - P.transpose()).cwiseAbs().maxCoeff() / scale);
    // The held states' rows are zero by construction (not estimated, filter/error_model.hpp).
    const Eigen::LLT<Mat21> llt(estimated_block(P, subs_[i].process_noise()));
    if (llt.info() != Eigen::Success || !(scale > 0.0)) ++stats_.covariance_not_pd;
  }
}

void Navigator::finish() { faults_->finish(stats_.t_end); }

}  // namespace wheelins
