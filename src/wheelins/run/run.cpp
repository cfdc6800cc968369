// One navigation run (run.hpp): the request's checks, the files read through the input
// checks and merged, the navigator, the writers on a second thread, the staged outputs.
#include "wheelins/run/run.hpp"

#include "wheelins/run/noise_report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>

#include "wheelins/run/input_checks.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/io/record_pipe.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/util/interrupt.hpp"
#include "wheelins/util/progress.hpp"
#include "wheelins/survey/checks.hpp"

namespace wheelins {
namespace fs = std::filesystem;

namespace {
const char* extension(TrajectoryFormat f) {
  switch (f) {
    case TrajectoryFormat::kTum: return ".tum";
    case TrajectoryFormat::kKml: return ".kml";
    default: return ".csv";
  }
}
bool multi(const RunRequest& r) { return r.modules.size() > 1 && r.write_subsystems; }

/// Which records of one stream go to its files (RunRequest::file_interval): the first at or
/// after each step of the interval from the first record, and the last one (held back until
/// the end). No allocation: one record is held.
class FileThinning {
 public:
  explicit FileThinning(double interval) : interval_(interval) {}
  /// True: write `rec` now; false: it is passed over (and held, in case it is the last).
  bool keep(const TrajectoryRecord& rec) {
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
  /// The stream's last record if it was passed over.
  const std::optional<TrajectoryRecord>& held() const { return held_; }

 private:
  double interval_;
  double next_ = 0.0;
  bool started_ = false;
  std::optional<TrajectoryRecord> held_;
};
/// weights.csv: a run of several modules with the position constraint.
bool writes_weights(const RunRequest& r) {
  return r.modules.size() > 1 && r.nav.fusion.position_constraint;
}

using io_detail::format_double;
using io_detail::quote;

std::string fmt(double v, const char* f = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

bool finite(const TrajectoryRecord& r) {
  return std::isfinite(r.t) && r.p_inN.allFinite() && r.v_inN.allFinite() && r.rpy.allFinite() &&
         r.p_std.allFinite() && r.v_std.allFinite() && r.rpy_std.allFinite();
}

}  // namespace

void validate_run_request(const RunRequest& r) {
  const std::string man = quote(r.manifest.path);
  if (r.modules.empty()) throw InputError("no module selected");
  std::set<std::string> seen;
  for (const auto& m : r.modules) {
    if (!seen.insert(m).second)
      throw InputError("module '" + m + "' is listed twice; each module can be used once in a run");
    if (!r.manifest.find(m)) throw InputError(man + ": no module named '" + m + "'");
  }
  // The odometer file the manifest names: the navigation does not read it (the wheels'
  // IMUs measure the speed), but a manifest naming a file that is not there is wrong, and
  // said so rather than passed over.
  if (r.manifest.odometer_file) {
    const fs::path f = r.manifest.resolve(*r.manifest.odometer_file);
    std::error_code ec;
    if (!fs::is_regular_file(f, ec))
      throw InputError(man + ": key 'odometer': '" + f.string() + "' " +
                       (fs::exists(f, ec) ? "is not a regular file" : "does not exist") +
                       " (fix the path, or remove the key: the run does not need an odometer)");
  }
  std::set<TrajectoryFormat> formats;
  for (TrajectoryFormat f : r.formats)
    if (!formats.insert(f).second)
      throw InputError(std::string("output format '") + extension(f) + "' is listed twice");
  if (!(r.max_duration >= 0.0 && r.max_duration <= 1e7))
    throw InputError("duration: must be in (0, 1e7] s (0: all the data), got " + format_double(r.max_duration));
  const NavigatorOptions& n = r.nav;
  if (!(n.output_interval >= 0.0 && n.output_interval <= 5.0))
    throw InputError("output interval: must be in [0, 5] s (0 = every epoch; the evaluation "
                     "interpolates across at most 5 s), got " + format_double(n.output_interval));
  if (!(r.file_interval >= 0.0 && r.file_interval <= 5.0))
    throw InputError("file interval (output.file_interval_s): must be in [0, 5] s (0 = every "
                     "record), got " + format_double(r.file_interval));
  n.validate();  // the navigator's own ranges (the covariance interval, the update intervals)
  if (n.fusion.centralized && r.modules.size() < 2)
    throw InputError("the centralized filter joins several IMUs; a run of one module ('" +
                     r.modules.front() + "') has nothing to join (drop --centralized / "
                     "fusion.centralized, or choose a multi-IMU configuration)");
  if (!n.fusion.weights.empty()) {
    if (n.fusion.weights.size() != r.modules.size())
      throw InputError("fusion weights: " + std::to_string(n.fusion.weights.size()) + " given for " +
                       std::to_string(r.modules.size()) + " modules");
    for (double w : n.fusion.weights)
      if (!(w > 0.0 && w <= 1e6))
        throw InputError("fusion weights: must be in (0, 1e6], got " + format_double(w) +
                         " (leave a module out instead of weighting it 0)");
  }
  if (n.faults.enabled)
    for (const auto& name : r.modules) {
      const ModuleSpec& s = *r.manifest.find(name);
      if (1.5 / s.rate_hz >= n.faults.max_gap)
        throw InputError(man + ": module '" + name + "' is declared at " + format_double(s.rate_hz) +
                         " Hz: its sample interval " + fmt(1.0 / s.rate_hz, "%.4g") +
                         " s is too close to faults.max_gap_s " + format_double(n.faults.max_gap) +
                         " s, so its samples would be taken for gaps (the module restarted on each); "
                         "IMU data above " + fmt(1.5 / n.faults.max_gap, "%.3g") +
                         " Hz are needed, or a larger faults.max_gap_s");
    }
}

std::vector<std::string> check_manifest_against_data(const Manifest& m, const std::vector<std::string>& modules,
                                                     const WarningSink& warn) {
  survey::SurveyOptions so;
  so.series.max_span = 300.0;  // the checks need minutes of driving, not hours
  for (const auto& name : modules)
    if (const ModuleSpec* s = m.find(name); s && s->steered) so.steered.push_back(name);
  const survey::DatasetSurvey s = survey::survey_modules(survey::survey_inputs(m, modules), so);
  std::string errors;
  for (const auto& c : survey::check_against_data(m, modules, s)) {
    if (c.level == survey::DataCheck::Level::kError)
      errors += "\n  " + c.message;
    else if (warn)
      warn(quote(m.path) + ": " + c.message);
  }
  if (!errors.empty())
    throw InputError(quote(m.path) + ": the manifest disagrees with its data:" + errors +
                     "\n(what the data show is checked before a run; --no-data-checks, or data_checks: false in a "
                     "run configuration, runs the manifest as it is)");
  return s.notes;
}

std::vector<fs::path> run_output_files(const RunRequest& r) {
  std::vector<fs::path> files;
  if (r.output_dir.empty()) return files;
  for (TrajectoryFormat f : r.formats) files.push_back(r.output_dir / (std::string("trajectory") + extension(f)));
  if (multi(r))
    for (const auto& m : r.modules) files.push_back(r.output_dir / (m + ".csv"));
  files.push_back(r.output_dir / "faults.csv");
  files.push_back(r.output_dir / "noise.yaml");
  if (r.calibration == CalibrationMode::kEstimate) files.push_back(r.output_dir / "calibration.yaml");
  if (writes_weights(r)) files.push_back(r.output_dir / "weights.csv");
  return files;
}

RunResult run_navigation(const RunRequest& r) {
  const auto wall0 = std::chrono::steady_clock::now();
  validate_run_request(r);
  // The output directory appears complete or not at all (io/output_dir.hpp); it is checked,
  // locked and staged before any work, so a refusal or an unwritable place costs nothing.
  const std::vector<fs::path> outputs = run_output_files(r);
  for (std::size_t i = 0; i < outputs.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (outputs[i] == outputs[j])
        throw InputError(quote(r.manifest.path) + ": two outputs of this run would be " + quote(outputs[i]) +
                         " (a module named like one of the run's own files?); rename the module");
  std::unique_ptr<OutputDir> out_dir;
  if (!r.output_dir.empty()) {
    OutputDirOptions o;
    o.overwrite = r.overwrite;
    o.kind = "results";
    o.inputs.push_back(r.manifest.path);
    for (const auto& name : r.modules) o.inputs.push_back(r.manifest.resolve(r.manifest.find(name)->file));
    if (r.manifest.truth_file) o.inputs.push_back(r.manifest.resolve(*r.manifest.truth_file));
    o.notice = r.warn;
    out_dir = std::make_unique<OutputDir>(r.output_dir, o);
  }
  auto staged = [&](const fs::path& final_file) { return out_dir->staging() / final_file.filename(); };
  if (r.data_checks) check_manifest_against_data(r.manifest, r.modules, r.warn);

  // The installation calibration pass: the Wheel-IMUs' files read once before navigating.
  InstallationCalibration calibration;
  if (r.calibration == CalibrationMode::kEstimate)
    calibration = calibrate_installation(r.manifest, r.modules, r.calibration_options,
                                         r.nav.faults.enabled, r.progress,
                                         r.max_duration > 0.0 ? r.manifest.static_end + r.max_duration
                                                              : std::numeric_limits<double>::infinity());
  const Manifest manifest = apply_calibration(r.manifest, calibration);

  // Readers for the selected modules only, merged by time; each through the input checks.
  std::vector<std::unique_ptr<ImuStream>> readers;
  std::vector<CheckedStream*> checked;
  std::uint64_t total_rows = 0;
  for (const auto& name : r.modules) {
    const ModuleSpec* spec = r.manifest.find(name);
    const fs::path file = r.manifest.resolve(spec->file);
    ImuReadOptions ro = imu_read_options(*spec, r.warn);
    ro.pass_nonfinite = r.nav.faults.enabled;  // one policy for a sample that cannot be: a fault
    auto reader = std::make_unique<ImuFileReader>(file, ro);
    auto c = std::make_unique<CheckedStream>(std::move(reader), *spec, r.manifest, r.nav.faults.enabled, r.warn);
    checked.push_back(c.get());
    readers.push_back(std::move(c));
    std::error_code ec;
    if (spec->layout == FileLayout::kBinary) total_rows += fs::file_size(file, ec) / (7 * sizeof(double));
  }
  ImuMerger merger(std::move(readers));
  // The record index of every stream's next sample (the merger holds one ahead), so that an
  // error of the navigation names the record it came at.
  std::vector<std::uint64_t> head_record(checked.size());
  for (std::size_t k = 0; k < checked.size(); ++k) head_record[k] = checked[k]->reader().index();

  // Writers: the vehicle solution in every format, the subsystems as CSV.
  TrajectoryWriterOptions wopt;
  wopt.tum_frame = r.tum_frame;
  wopt.origin = r.manifest.origin;  // the local frame of the records' p_inN
  std::vector<std::unique_ptr<TrajectoryWriter>> vehicle, subsystems;
  if (out_dir) {
    for (TrajectoryFormat f : r.formats)
      vehicle.push_back(make_trajectory_writer(
          f, out_dir->staging() / (std::string("trajectory") + extension(f)), wopt));
    if (multi(r))
      for (const auto& m : r.modules)
        subsystems.push_back(
            make_trajectory_writer(TrajectoryFormat::kCsv, out_dir->staging() / (m + ".csv"), wopt));
  }

  // Text formatting and file writing run on a second thread (RecordPipe), fed in batches;
  // the in-memory consumer (on_record) stays on this one.
  const bool writing = !vehicle.empty() || !subsystems.empty();
  std::unique_ptr<RecordPipe> pipe;
  if (writing)
    pipe = std::make_unique<RecordPipe>([&](int stream, const TrajectoryRecord& rec) {
      if (stream == 0) {
        for (auto& w : vehicle) w->write(rec);
      } else if (!subsystems.empty()) {
        subsystems[stream - 1]->write(rec);
      }
    });
  NavigatorOptions nav_opt = r.nav;
  nav_opt.module_records = !subsystems.empty();  // only when their files are written
  std::vector<FileThinning> thinning(1 + subsystems.size(), FileThinning(r.file_interval));
  // What the records are used for (the caller's consumer, e.g. the streaming evaluation,
  // and the hand-over to the writer thread, which waits when the writer is behind) is
  // timed here and left out of filter_seconds. A record that is not finite is never
  // passed on: the run stops at the end of the block with the module, time and cause.
  double sink_seconds = 0.0;
  int bad_stream = -1;
  double bad_t = 0.0;
  Navigator nav(manifest, r.modules, nav_opt, [&](int stream, const TrajectoryRecord& rec) {
    if (bad_stream >= 0) return;
    if (!finite(rec)) {
      bad_stream = stream;
      bad_t = rec.t;
      return;
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (stream == 0 && r.on_record) r.on_record(rec);
    if (pipe && thinning[static_cast<std::size_t>(stream)].keep(rec)) pipe->push(stream, rec);
    sink_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  });
  // Where the solution stopped being finite: the first subsystem whose state or covariance
  // is not, else the stream of the record.
  auto check_finite = [&](double t_now) {
    std::string module, cause;
    for (int i = 0; i < nav.subsystem_count() && module.empty(); ++i) {
      const StrapdownEkf& ekf = nav.subsystem(i).ekf();
      const NavState& x = ekf.state();
      if (!(x.p_IinW.allFinite() && x.v_IinW.allFinite() && x.q_ItoW.coeffs().allFinite()))
        module = r.modules[static_cast<std::size_t>(i)], cause = "its position, velocity or attitude";
      else if (!ekf.covariance().allFinite())
        module = r.modules[static_cast<std::size_t>(i)], cause = "its covariance";
    }
    if (module.empty() && bad_stream < 0) return;
    if (module.empty()) {
      module = bad_stream == 0 ? std::string("the vehicle solution") : r.modules[static_cast<std::size_t>(bad_stream - 1)];
      cause = "its output record";
    }
    const double t = bad_stream >= 0 ? bad_t : t_now;
    throw InputError("'" + module + "': the navigation became non-finite (" + cause + ") by t = " +
                     format_double(t) + " s, " + fmt(t - nav.stats().t_start, "%.1f") +
                     " s after the start: the filter diverged (an input or a setting outside what "
                     "the checks catch); nothing was written");
  };

  Progress progress("navigating", total_rows, r.progress);
  // Samples are read in blocks, and only the processing of a block is timed: the
  // filter's own cost, without file reading, at two clock reads per 4096 samples.
  constexpr std::size_t kBlock = 4096;
  std::vector<std::pair<std::size_t, ImuSample>> block(kBlock);
  std::vector<std::uint64_t> record(kBlock);
  std::uint64_t n = 0;
  double filter_seconds = 0.0;
  bool more = true, stop = false;
  while (more && !stop) {
    std::size_t count = 0;
    while (count < kBlock && (more = merger.next(block[count].first, block[count].second))) {
      const std::size_t k = block[count].first;
      record[count] = head_record[k];
      head_record[k] = checked[k]->reader().index();
      ++count;
    }
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < count; ++k) {
      const ImuSample& s = block[k].second;
      try {
        nav.process(static_cast<int>(block[k].first), s);
      } catch (const OutageError& e) {
        throw InputError(std::string(e.what()) + " (record " + std::to_string(record[k]) +
                         ", 0-based, is the first after the gap); nothing was written. Cut the data at the "
                         "gap and run the parts apart, or raise faults.max_outage_s");
      }
      if (r.max_duration > 0 && nav.navigating() && s.t - nav.stats().t_start >= r.max_duration) {
        stop = true;
        break;
      }
    }
    filter_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    n += count;
    if (count) check_finite(block[count - 1].second.t);
    progress.update(n);  // also where an interrupt stops the run (nothing is written)
  }
  progress.finish();
  if (!nav.navigating()) {
    char period[96];
    std::snprintf(period, sizeof period, "[%.3f, %.3f] s", r.manifest.static_start,
                  r.manifest.static_end);
    std::string files;
    for (const auto& name : r.modules)
      files += (files.empty() ? "'" : ", '") + r.manifest.resolve(r.manifest.find(name)->file).string() + "'";
    throw InputError(files + ": the data end before the static period " + period + " of '" +
                     r.manifest.path.string() + "' does: nothing to navigate");
  }

  nav.finish();
  check_finite(nav.stats().t_end);
  if (r.warn)
    for (const auto& w : nav.faults().warnings()) r.warn(w);
  if (pipe) {
    for (std::size_t k = 0; k < thinning.size(); ++k)  // the files end where the run ended
      if (thinning[k].held()) pipe->push(static_cast<int>(k), *thinning[k].held());
    pipe->finish();  // every record written (or the writer's error thrown)
  }
  RunResult result;
  for (auto& w : vehicle) w->commit();
  for (auto& w : subsystems) w->commit();
  std::string input_faults;
  for (std::size_t i = 0; i < checked.size(); ++i)
    if (checked[i]->dropped())
      input_faults += "  " + r.modules[i] + ": " + std::to_string(checked[i]->dropped()) +
                      " samples beyond the sensor range or not finite left out (" + quote(checked[i]->reader().file()) + ")\n";
  if (out_dir) {
    std::string csv = fault_report_csv(nav.faults());
    for (std::size_t i = 0; i < checked.size(); ++i)
      if (checked[i]->dropped())
        csv += "# input: " + r.modules[i] + ",samples_beyond_range," + std::to_string(checked[i]->dropped()) + "\n";
    AtomicTextFile report(staged(r.output_dir / "faults.csv"), false);
    report.write(csv);
    report.commit();
  }
  for (int i = 0; i < nav.subsystem_count(); ++i) result.noise.push_back(nav.noise_report(i));
  result.noise_report = noise_report_text(result.noise, r.manifest, r.nav.noise.enabled);
  if (out_dir) {
    AtomicTextFile noise(staged(r.output_dir / "noise.yaml"), false);
    noise.write(noise_report_yaml(result.noise, r.manifest, r.nav.noise.enabled));
    noise.commit();
    if (r.calibration == CalibrationMode::kEstimate) {
      AtomicTextFile cal(staged(r.output_dir / "calibration.yaml"), false);
      cal.write(calibration_yaml(calibration, r.manifest));
      cal.commit();
    }
    if (writes_weights(r)) {
      AtomicTextFile weights(staged(r.output_dir / "weights.csv"), false);
      weights.write(weights_csv(nav.weight_history(), r.modules));
      weights.commit();
    }
    out_dir->commit();  // every file appears at once
  }
  if (r.calibration == CalibrationMode::kEstimate) result.calibration_report = calibration_report(calibration);
  result.calibration = std::move(calibration);
  result.weights = nav.weight_history();
  result.weights_report = weights_report(result.weights, r.modules, r.nav.fusion);
  result.fault_report = fault_report_text(nav.faults());
  if (!input_faults.empty()) {
    if (result.fault_report.rfind("faults: none detected", 0) == 0) result.fault_report = "faults:\n" + result.fault_report.substr(22);
    result.fault_report = "input faults:\n" + input_faults + result.fault_report;
  }
  result.fault_events = nav.faults().events();
  for (int i = 0; i < nav.faults().size(); ++i) result.fault_stats.push_back(nav.faults().stats(i));
  result.files = outputs;
  for (auto& f : result.files) f = out_dir ? out_dir->final_path(f.filename()) : f;
  result.stats = nav.stats();
  result.filter_seconds = std::max(0.0, filter_seconds - sink_seconds);
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

}  // namespace wheelins
