// One run's pipeline between its input and its results (session.hpp).
#include "wheelins/run/session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/run/noise_report.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::format_double;
using io_detail::quote;

namespace {
bool finite(const TrajectoryRecord& r) {
  return std::isfinite(r.t) && r.p_inN.allFinite() && r.v_inN.allFinite() && r.rpy.allFinite() &&
         r.p_std.allFinite() && r.v_std.allFinite() && r.rpy_std.allFinite();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

bool FileThinning::keep(const TrajectoryRecord& rec) {
  if (interval_ <= 0.0) return true;
  if (started_ && rec.t + 1e-9 < next_) {
    held_ = rec;
    return false;
  }
  if (!started_) next_ = rec.t, started_ = true;
  while (next_ <= rec.t + 1e-9) next_ += interval_;
  held_.reset();
  return true;
}

RunSession::RunSession(RunRequest request, const InstallationCalibration* calibration)
    : wall0_(std::chrono::steady_clock::now()), req_(std::move(request)) {
  validate_run_request(req_);
  // The truth is opened first: a file that cannot be read stops the run before any work.
  if (req_.evaluation && req_.manifest.truth_file)
    evaluation_ = std::make_unique<eval::RunEvaluation>(req_.manifest.resolve(*req_.manifest.truth_file),
                                                        req_.manifest.origin,
                                                        run_evaluation_options(req_.manifest, *req_.evaluation));
  stage_outputs();
  if (req_.data_checks) check_manifest_against_data(req_.manifest, req_.modules, req_.warn);
  if (req_.calibration == CalibrationMode::kEstimate) {
    if (calibration)
      calibration_ = *calibration;
    else  // the first pass: the Wheel-IMUs' files read once before navigating
      calibration_ = calibrate_installation(
          req_.manifest, req_.modules, req_.calibration_options, req_.nav.faults.enabled, req_.progress,
          req_.max_duration > 0.0 ? req_.manifest.static_end + req_.max_duration
                                  : std::numeric_limits<double>::infinity());
  }
  manifest_ = apply_calibration(req_.manifest, calibration_);
  open_writers();
  make_navigator();
}

RunSession::~RunSession() = default;

// The output directory appears complete or not at all (io/output_dir.hpp); it is checked,
// locked and staged before any work.
void RunSession::stage_outputs() {
  outputs_ = run_output_files(req_);
  for (std::size_t i = 0; i < outputs_.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (outputs_[i] == outputs_[j])
        throw InputError(quote(req_.manifest.path) + ": two outputs of this run would be " + quote(outputs_[i]) +
                         " (a module named like one of the run's own files?); rename the module");
  if (req_.output_dir.empty()) return;
  OutputDirOptions o;
  o.overwrite = req_.overwrite;
  o.kind = "results";
  o.inputs.push_back(req_.manifest.path);
  for (const auto& name : req_.modules) o.inputs.push_back(req_.manifest.resolve(req_.manifest.find(name)->file));
  if (req_.manifest.truth_file) o.inputs.push_back(req_.manifest.resolve(*req_.manifest.truth_file));
  o.notice = req_.warn;
  out_dir_ = std::make_unique<OutputDir>(req_.output_dir, o);
}

// The vehicle solution in every format, the subsystems as CSV; text formatting and file
// writing on a second thread (RecordPipe), fed in batches.
void RunSession::open_writers() {
  if (out_dir_) {
    TrajectoryWriterOptions wopt;
    wopt.tum_frame = req_.tum_frame;
    wopt.origin = req_.manifest.origin;  // the local frame of the records' p_inN
    for (std::size_t i = 0; i < req_.formats.size(); ++i)  // run_output_files() lists them first
      vehicle_.push_back(make_trajectory_writer(req_.formats[i], out_dir_->staging() / outputs_[i].filename(), wopt));
    if (writes_subsystem_files(req_))
      for (const auto& m : req_.modules)
        subsystems_.push_back(
            make_trajectory_writer(TrajectoryFormat::kCsv, out_dir_->staging() / (m + ".csv"), wopt));
  }
  thinning_.assign(1 + subsystems_.size(), FileThinning(req_.file_interval));
  if (vehicle_.empty() && subsystems_.empty()) return;
  pipe_ = std::make_unique<RecordPipe>([this](int stream, const TrajectoryRecord& rec) {
    if (stream == 0) {
      for (auto& w : vehicle_) w->write(rec);
    } else if (!subsystems_.empty()) {
      subsystems_[static_cast<std::size_t>(stream - 1)]->write(rec);
    }
  });
}

void RunSession::make_navigator() {
  NavigatorOptions nav_opt = req_.nav;
  nav_opt.module_records = !subsystems_.empty();  // only when their files are written
  nav_ = std::make_unique<Navigator>(manifest_, req_.modules, nav_opt,
                                     [this](int stream, const TrajectoryRecord& rec) { on_record(stream, rec); });
}

// What the records are used for (the caller's consumer, e.g. the streaming evaluation, and
// the hand-over to the writer thread, which waits when the writer is behind) is timed here
// and left out of filter_seconds. A record that is not finite is never passed on: the run
// stops at check_finite() with the module, time and cause.
void RunSession::on_record(int stream, const TrajectoryRecord& rec) {
  if (bad_stream_ >= 0) return;
  if (!finite(rec)) {
    bad_stream_ = stream;
    bad_t_ = rec.t;
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (stream == 0 && evaluation_) evaluation_->add(rec);
  if (stream == 0 && req_.on_record) req_.on_record(rec);
  if (pipe_ && thinning_[static_cast<std::size_t>(stream)].keep(rec)) pipe_->push(stream, rec);
  sink_seconds_ += seconds_since(t0);
}

bool RunSession::push(int module, const ImuSample& s, std::uint64_t record) {
  started_ = true;
  try {
    nav_->process(module, s);
  } catch (const OutageError& e) {
    throw InputError(std::string(e.what()) + " (record " + std::to_string(record) +
                     ", 0-based, is the first after the gap); nothing was written. Cut the data at the "
                     "gap and run the parts apart, or raise faults.max_outage_s");
  }
  return !(req_.max_duration > 0 && nav_->navigating() && s.t - nav_->start_time() >= req_.max_duration);
}

// Where the solution stopped being finite: the first subsystem whose state or covariance is
// not, else the stream of the record.
void RunSession::check_finite(double t_now) const {
  std::string module, cause;
  for (int i = 0; i < nav_->subsystem_count() && module.empty(); ++i) {
    const StrapdownEkf& ekf = nav_->subsystem(i).ekf();
    const NavState& x = ekf.state();
    if (!(x.p_IinW.allFinite() && x.v_IinW.allFinite() && x.q_ItoW.coeffs().allFinite()))
      module = req_.modules[static_cast<std::size_t>(i)], cause = "its position, velocity or attitude";
    else if (!ekf.covariance().allFinite())
      module = req_.modules[static_cast<std::size_t>(i)], cause = "its covariance";
  }
  if (module.empty() && bad_stream_ < 0) return;
  if (module.empty()) {
    module = bad_stream_ == 0 ? std::string("the vehicle solution")
                              : req_.modules[static_cast<std::size_t>(bad_stream_ - 1)];
    cause = "its output record";
  }
  const double t = bad_stream_ >= 0 ? bad_t_ : t_now;
  char after[32];
  std::snprintf(after, sizeof after, "%.1f", t - nav_->start_time());
  throw InputError("'" + module + "': the navigation became non-finite (" + cause + ") by t = " + format_double(t) +
                   " s, " + after +
                   " s after the start: the filter diverged (an input or a setting outside what "
                   "the checks catch); nothing was written");
}

void RunSession::require_navigating(const std::vector<SessionInput>& inputs) const {
  if (nav_->navigating()) return;
  char period[96];
  std::snprintf(period, sizeof period, "[%.3f, %.3f] s", req_.manifest.static_start, req_.manifest.static_end);
  std::string sources;
  for (const auto& in : inputs) sources += (sources.empty() ? "" : ", ") + quote(in.source);
  throw InputError(sources + ": the data end before the static period " + period + " of " +
                   quote(req_.manifest.path) + " does: nothing to navigate");
}

void RunSession::use_calibration(const InstallationCalibration& calibration) {
  if (started_) throw std::logic_error("RunSession::use_calibration after the first sample");
  calibration_ = calibration;
  manifest_ = apply_calibration(req_.manifest, calibration_);
  make_navigator();
}

// faults.csv, noise.yaml, calibration.yaml, weights.csv into the staging directory, then
// every file appears at once.
void RunSession::write_reports(const std::string& input_csv, const std::vector<ModuleNoiseReport>& noise) {
  if (!out_dir_) return;
  auto write = [&](const char* name, const std::string& text) {
    AtomicTextFile f(out_dir_->staging() / name, false);
    f.write(text);
    f.commit();
  };
  write("faults.csv", fault_report_csv(nav_->faults()) + input_csv);
  write("noise.yaml", noise_report_yaml(noise, req_.manifest, req_.nav.noise.enabled));
  if (req_.calibration == CalibrationMode::kEstimate)
    write("calibration.yaml", calibration_yaml(calibration_, req_.manifest));
  if (writes_weights_file(req_)) write("weights.csv", weights_csv(nav_->weight_history(), req_.modules));
  out_dir_->commit();
}

RunResult RunSession::finish(double process_seconds, const std::vector<SessionInput>& inputs) {
  require_navigating(inputs);
  nav_->finish();
  check_finite(nav_->stats().t_end);
  if (req_.warn)
    for (const auto& w : nav_->faults().warnings()) req_.warn(w);
  if (pipe_) {
    for (std::size_t k = 0; k < thinning_.size(); ++k)  // the files end where the run ended
      if (thinning_[k].held()) pipe_->push(static_cast<int>(k), *thinning_[k].held());
    pipe_->finish();  // every record written (or the writer's error thrown)
  }
  for (auto& w : vehicle_) w->commit();
  for (auto& w : subsystems_) w->commit();
  std::string input_faults, input_csv;
  for (std::size_t i = 0; i < inputs.size() && i < req_.modules.size(); ++i) {
    if (!inputs[i].dropped) continue;
    const std::string n = std::to_string(inputs[i].dropped);
    input_faults += "  " + req_.modules[i] + ": " + n + " samples beyond the sensor range or not finite left out (" +
                    quote(inputs[i].source) + ")\n";
    input_csv += "# input: " + req_.modules[i] + ",samples_beyond_range," + n + "\n";
  }
  RunResult result;
  for (int i = 0; i < nav_->subsystem_count(); ++i) result.noise.push_back(nav_->noise_report(i));
  write_reports(input_csv, result.noise);
  result.noise_report = noise_report_text(result.noise, req_.manifest, req_.nav.noise.enabled);
  if (req_.calibration == CalibrationMode::kEstimate) result.calibration_report = calibration_report(calibration_);
  result.calibration = std::move(calibration_);
  result.weights = nav_->weight_history();
  std::vector<bool> follows(req_.modules.size());
  for (int i = 0; i < nav_->subsystem_count(); ++i) follows[i] = nav_->follows(i);
  result.weight_summary = summarize_weights(result.weights, static_cast<int>(req_.modules.size()), follows);
  result.weights_report = weights_report(result.weight_summary, result.weights.size(), req_.modules, req_.nav.fusion);
  result.fault_report = fault_report_text(nav_->faults());
  if (!input_faults.empty()) {
    if (result.fault_report.rfind("faults: none detected", 0) == 0)
      result.fault_report = "faults:\n" + result.fault_report.substr(22);
    result.fault_report = "input faults:\n" + input_faults + result.fault_report;
  }
  result.fault_events = nav_->faults().events();
  for (int i = 0; i < nav_->faults().size(); ++i) result.fault_stats.push_back(nav_->faults().stats(i));
  result.files = outputs_;
  for (auto& f : result.files) f = out_dir_ ? out_dir_->final_path(f.filename()) : f;
  result.stats = nav_->stats();
  result.filter_seconds = std::max(0.0, process_seconds - sink_seconds_);
  finish_evaluation(result);
  result.wall_seconds = seconds_since(wall0_);
  return result;
}

void RunSession::finish_evaluation(RunResult& result) {
  if (!evaluation_) return;
  result.truth_file = evaluation_->truth().file();
  try {
    result.evaluation = evaluation_->finish();
  } catch (const InputError& e) {
    result.evaluation_error = std::string(e.what()) + (req_.output_dir.empty() ? "" : " (the trajectory was written)");
  }
}

}  // namespace wheelins
