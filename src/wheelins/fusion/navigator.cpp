// The navigator of navigator.hpp: alignment, the per-sample flow of process(), the
// velocity and position-constraint steps, and the bookkeeping (stats, covariance health).
#include "wheelins/fusion/navigator.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

namespace wheelins {

namespace {
/// An aid's step when it is due at t_all (the time of the subsystem in use furthest behind),
/// every covariance brought to that epoch first: outside the timed step, since the time update
/// is not the step's cost (the paper's Table 8).
template <class Aid, class Step>
void step_when_due(Aid& aid, double t_all, FilterBackend& filter, Step&& step) {
  if (!aid.schedule().due(t_all)) return;
  filter.flush();
  const auto t0 = std::chrono::steady_clock::now();
  step();
  AidStats& stats = aid.stats();
  stats.step_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++stats.steps;
  aid.schedule().advance(t_all);
}

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
      ctx_{opt_, subs_, *filter_, *faults_, output_, noise_, shared_, meas_},
      velocity_(ctx_),
      zero_motion_(ctx_),
      position_(ctx_) {
  opt_.validate();
  static_.resize(subs_.size());
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
  const bool navigate = faults_->on_sample(index, raw, b);
  ctx_.act_on_faults();
  if (!navigate) return;
  // A steered wheel's start takes the vehicle's heading from an IMU that does not steer.
  if (s.is_wheel() && !subs_.wheel(index).steering_settled())
    subs_.wheel(index).set_reference_heading(unsteered_heading(index));
  // Mechanization, and the covariance time update when due (the filter's).
  s.propagate(b);
  filter_->propagated(index);
  zero_motion_.add(index, b);
  if (s.is_wheel()) faults_->tally_rotation(index, b);

  // Each aid steps when every subsystem in use has reached its epoch.
  const double t_all = ctx_.min_time();
  step_when_due(velocity_, t_all, *filter_, [&] {
    velocity_epoch(t_all);
    check_covariances();
  });
  if (position_.active()) step_when_due(position_, t_all, *filter_, [&] { position_.step(); });

  // Output at the epochs of the first module in use.
  if (index != output_driver()) return;
  ++stats_.epochs;
  stats_.t_end = raw.t;
  // (raw.t > last: when the driving module changes, the new one may share the epoch.)
  if (raw.t + 1e-9 >= next_output_t_ && raw.t > last_output_t_) {
    last_output_t_ = raw.t;
    output_.write(raw.t, ctx_.vehicle_modules(), ctx_.in_use());
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
  velocity_.schedule().start(t0);
  position_.schedule().start(t0);
}

// ------------------------------------------------------------------ the aids' epochs

void Navigator::velocity_epoch(double t) {
  velocity_.begin_epoch(t);
  if (zero_motion_.standing(t))
    zero_motion_.step();
  else
    velocity_.step(t);
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

// ------------------------------------------------------------------ bookkeeping

int Navigator::output_driver() const {
  for (int i = 0; i < subs_.size(); ++i)
    if (faults_->in_use(i)) return i;
  return -1;
}

TrajectoryRecord Navigator::vehicle_record() const { return output_.fused(ctx_.vehicle_modules()); }

const NavigatorStats& Navigator::stats() const {
  const AidStats& v = velocity_.stats();
  const AidStats& p = position_.stats();
  stats_.velocity_steps = v.steps;
  stats_.velocity_step_seconds = v.step_seconds;
  stats_.velocity_updates = v.updates;
  stats_.velocity_rejected = v.rejected;
  stats_.max_velocity_test_ratio = v.max_test_ratio;
  stats_.standstill_steps = zero_motion_.steps();
  stats_.zero_motion_updates = zero_motion_.updates();
  stats_.position_steps = p.steps;
  stats_.position_step_seconds = p.step_seconds;
  stats_.position_updates = p.updates;
  stats_.position_rejected = p.rejected;
  stats_.max_position_test_ratio = p.max_test_ratio;
  return stats_;
}

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
