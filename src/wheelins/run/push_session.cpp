// A run fed with pushed records (push_session.hpp).
#include "wheelins/run/push_session.hpp"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <limits>

#include "wheelins/io/text_util.hpp"

namespace wheelins {
using io_detail::format_double;

namespace {
RunRequest pushed(RunRequest r) {
  r.data_checks = false;  // they read the files; the samples come from elsewhere
  r.progress = false;     // the end is not known
  return r;
}
}  // namespace

PushSession::PushSession(RunRequest request, double calibration_warmup, std::string source)
    : source_(std::move(source)) {
  const bool estimate = request.calibration == CalibrationMode::kEstimate;
  if (estimate && !(calibration_warmup > 0.0 && std::isfinite(calibration_warmup)))
    throw InputError("calibration_warmup must be a positive number of seconds (given " +
                     format_double(calibration_warmup) + ")");
  // Built now in any case, so that every setting is checked here; with a warm-up the
  // navigator is built again, on the estimates, when the warm-up ends.
  session_ = std::make_unique<RunSession>(pushed(std::move(request)), &calibration_);
  const RunRequest& r = session_->request();
  if (estimate) {
    // As a run with a duration: the estimates from no sample past it.
    const double w = r.max_duration > 0.0 ? std::min(calibration_warmup, r.max_duration) : calibration_warmup;
    warmup_ = std::make_unique<CalibrationWarmup>(r.manifest, r.modules, r.calibration_options, w);
  }
  tracks_.reserve(r.modules.size());  // (InputChecks keeps a reference to its spec)
  for (const auto& name : r.modules) {
    const ModuleSpec* spec = r.manifest.find(name);
    tracks_.push_back(Track{imu_read_options(*spec), 0.0, 0,
                            InputChecks(*spec, r.manifest, r.nav.faults.enabled, r.warn,
                                        "module '" + name + "' (" + source_ + ")")});
  }
}

PushSession::~PushSession() = default;

double PushSession::warmup_end() const { return warmup_ ? warmup_->end() : 0.0; }

// The record made into a sample as ImuFileReader makes it, and held to the input checks;
// `admitted` false: left out (beyond the sensor range).
ImuSample PushSession::checked_sample(int module, const ImuRow& row, bool& admitted) {
  Track& tr = tracks_[static_cast<std::size_t>(module)];
  // Made only for an error: a sample that passes allocates nothing.
  auto where = [&] {
    return "module '" + request().modules[static_cast<std::size_t>(module)] + "', sample " +
           std::to_string(tr.count) + " (0-based)";
  };
  const double v[7] = {row.t, row.gyro.x(), row.gyro.y(), row.gyro.z(), row.accel.x(), row.accel.y(), row.accel.z()};
  for (int c = 0; c < 7; ++c)
    if (!std::isfinite(v[c]))
      throw RejectedSample(where() + ", column " + std::to_string(c) + " (" + kImuColumnNames[c] + "): value is " +
                       (std::isnan(v[c]) ? "NaN" : "infinite"));
  double dt = 1.0 / tr.options.rate_hz;
  if (tr.count > 0) {
    dt = row.t - tr.prev_t;
    if (!(dt > 0.0))
      throw RejectedSample(where() + ": time " + format_double(row.t) +
                       (dt == 0.0 ? " repeats the previous sample's time"
                                  : " goes back from the previous sample's " + format_double(tr.prev_t)) +
                       " (timestamps must be strictly increasing)");
  }
  ImuSample s = imu_sample(row, dt, tr.options);
  if (s.t < last_t_)
    throw RejectedSample(where() + ": time " + format_double(s.t) + " is before the last sample pushed (" +
                     format_double(last_t_) + "): push the modules' samples in time order");
  tr.prev_t = row.t;
  last_t_ = s.t;
  admitted = tr.checks.admit(s, tr.count++);
  return s;
}

bool PushSession::push(int module, const ImuRow& row) {
  if (finished_) throw InputError("push after finish()");
  if (module < 0 || module >= static_cast<int>(tracks_.size()))
    throw InputError("module index " + std::to_string(module) + " out of range (0.." +
                     std::to_string(tracks_.size() - 1) + ")");
  if (stopped_) return false;
  bool admitted = false;
  const ImuSample s = checked_sample(module, row, admitted);
  const std::uint64_t record = tracks_[static_cast<std::size_t>(module)].count - 1;
  if (!admitted) return true;
  if (in_warmup()) {
    if (warmup_->add(module, s, record)) return true;
    end_warmup();
    if (stopped_) return false;
  }
  if (behind_) {
    pending_.push_back(Pending{module, s, record});
    catch_up(catch_up_per_push_);
    return !stopped_;
  }
  navigate(module, s, record);
  return !stopped_;
}

void PushSession::navigate(int module, const ImuSample& s, std::uint64_t record) {
  const auto t0 = std::chrono::steady_clock::now();
  stopped_ = !session_->push(module, s, record);
  process_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  session_->check_finite(s.t);
}

// The warm-up's estimates made, the navigator built with them and the kept samples navigated
// (all, or the first slice: set_catch_up()).
void PushSession::end_warmup() {
  calibration_ = warmup_->result();
  session_->use_calibration(calibration_);
  warmup_done_ = true;
  behind_ = true;
  caught_up_ = 0;
  catch_up(catch_up_per_push_ == 0 ? std::numeric_limits<std::size_t>::max() : catch_up_per_push_);
}

// Up to `n` of the samples behind navigated in order: the warm-up's kept ones, then those
// pushed since.
void PushSession::catch_up(std::size_t n) {
  const auto& kept = warmup_->kept();
  for (; n > 0 && !stopped_ && caught_up_ < kept.size() + pending_.size(); --n, ++caught_up_) {
    if (caught_up_ < kept.size()) {
      navigate(kept[caught_up_].index, kept[caught_up_].sample, kept[caught_up_].record);
    } else {
      const Pending& p = pending_[caught_up_ - kept.size()];
      navigate(p.module, p.sample, p.record);
    }
  }
  if (stopped_ || caught_up_ == kept.size() + pending_.size()) {
    warmup_->release();
    std::vector<Pending>().swap(pending_);
    behind_ = false;
  }
}

RunResult PushSession::finish() {
  if (finished_) throw InputError("finish() called twice");
  for (auto& tr : tracks_) tr.checks.finish();
  if (in_warmup()) end_warmup();  // the data ended inside the warm-up: estimates from all of it
  if (behind_) catch_up(std::numeric_limits<std::size_t>::max());
  std::vector<SessionInput> inputs;
  for (std::size_t i = 0; i < tracks_.size(); ++i) inputs.push_back(SessionInput{tracks_[i].checks.dropped(), source_ + " of " + request().modules[i]});
  finished_ = true;
  return session_->finish(process_seconds_, inputs);
}

}  // namespace wheelins
