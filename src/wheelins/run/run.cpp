// One navigation run (run.hpp): the request's checks, and the manifest's files read through
// the input checks, merged and fed to a RunSession (session.hpp).
#include "wheelins/run/run.hpp"

#include <chrono>
#include <cstdio>
#include <set>
#include <utility>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/run/input_checks.hpp"
#include "wheelins/run/run_options.hpp"
#include "wheelins/run/session.hpp"
#include "wheelins/survey/checks.hpp"
#include "wheelins/util/progress.hpp"

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

using io_detail::format_double;
using io_detail::quote;

std::string fmt(double v, const char* f = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

bool writes_subsystem_files(const RunRequest& r) { return r.modules.size() > 1 && r.write_subsystems; }
bool writes_weights_file(const RunRequest& r) { return r.modules.size() > 1 && r.nav.fusion.position_constraint; }

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
  const OptionRange out = run_option_range("output.interval_s"), file = run_option_range("output.file_interval_s");
  if (!(n.output_interval >= out.lo && n.output_interval <= out.hi))
    throw InputError("output interval: must be in [" + format_double(out.lo) + ", " + format_double(out.hi) +
                     "] s (0 = every epoch; the evaluation interpolates across at most 5 s), got " +
                     format_double(n.output_interval));
  if (!(r.file_interval >= file.lo && r.file_interval <= file.hi))
    throw InputError("file interval (output.file_interval_s): must be in [" + format_double(file.lo) + ", " +
                     format_double(file.hi) + "] s (0 = every record), got " + format_double(r.file_interval));
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
  if (writes_subsystem_files(r))
    for (const auto& m : r.modules) files.push_back(r.output_dir / (m + ".csv"));
  files.push_back(r.output_dir / "faults.csv");
  files.push_back(r.output_dir / "noise.yaml");
  if (r.calibration == CalibrationMode::kEstimate) files.push_back(r.output_dir / "calibration.yaml");
  if (writes_weights_file(r)) files.push_back(r.output_dir / "weights.csv");
  return files;
}

RunRequest calibration_run_request(const Manifest& m, std::vector<std::string> modules, double output_interval) {
  RunRequest req;
  req.manifest = m;
  req.modules = std::move(modules);
  req.calibration = CalibrationMode::kManifest;
  req.data_checks = false;
  req.progress = false;
  req.nav.output_interval = output_interval;
  req.warn = [](const std::string&) {};
  return req;
}

// The file feeder of a RunSession: the selected modules' files, each through its input
// checks, merged by time and pushed in blocks.
RunResult run_navigation(const RunRequest& r) {
  RunSession session(r);
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

  Progress progress("navigating", total_rows, r.progress);
  // Samples are read in blocks, and only the processing of a block is timed: the
  // filter's own cost, without file reading, at two clock reads per 4096 samples.
  constexpr std::size_t kBlock = 4096;
  std::vector<std::pair<std::size_t, ImuSample>> block(kBlock);
  std::vector<std::uint64_t> record(kBlock);
  std::uint64_t n = 0;
  double process_seconds = 0.0;
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
    for (std::size_t k = 0; k < count && !stop; ++k)
      stop = !session.push(static_cast<int>(block[k].first), block[k].second, record[k]);
    process_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    n += count;
    if (count) session.check_finite(block[count - 1].second.t);
    progress.update(n);  // also where an interrupt stops the run (nothing is written)
  }
  progress.finish();
  std::vector<SessionInput> inputs;
  for (const CheckedStream* c : checked) inputs.push_back(SessionInput{c->dropped(), c->reader().file().string()});
  return session.finish(process_seconds, inputs);
}

}  // namespace wheelins
