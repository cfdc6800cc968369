#include "wheelins/fusion/run.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/record_pipe.hpp"
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
bool multi(const RunRequest& r) { return r.modules.size() > 1 && r.write_subsystems; }
}  // namespace

std::vector<fs::path> run_output_files(const RunRequest& r) {
  std::vector<fs::path> files;
  if (r.output_dir.empty()) return files;
  for (TrajectoryFormat f : r.formats) files.push_back(r.output_dir / (std::string("trajectory") + extension(f)));
  if (multi(r))
    for (const auto& m : r.modules) files.push_back(r.output_dir / (m + ".csv"));
  files.push_back(r.output_dir / "faults.csv");
  return files;
}

RunResult run_navigation(const RunRequest& r) {
  const auto wall0 = std::chrono::steady_clock::now();
  // Refuse before doing any work if results would be overwritten.
  const std::vector<fs::path> outputs = run_output_files(r);
  for (const auto& f : outputs) check_output_target(f, r.overwrite);

  // Readers for the selected modules only, merged by time.
  std::vector<std::unique_ptr<ImuStream>> readers;
  std::uint64_t total_rows = 0;
  for (const auto& name : r.modules) {
    const ModuleSpec* spec = r.manifest.find(name);
    if (!spec) throw InputError("'" + r.manifest.path.string() + "': no module named '" + name + "'");
    const fs::path file = r.manifest.resolve(spec->file);
    readers.push_back(std::make_unique<ImuFileReader>(file, imu_read_options(*spec, r.warn)));
    std::error_code ec;
    if (spec->layout == FileLayout::kBinary) total_rows += fs::file_size(file, ec) / (7 * sizeof(double));
  }
  ImuMerger merger(std::move(readers));

  // Writers: the vehicle solution in every format, the subsystems as CSV.
  if (!r.output_dir.empty()) fs::create_directories(r.output_dir);
  TrajectoryWriterOptions wopt;
  wopt.overwrite = r.overwrite;
  std::vector<std::unique_ptr<TrajectoryWriter>> vehicle, subsystems;
  if (!r.output_dir.empty()) {
    for (TrajectoryFormat f : r.formats)
      vehicle.push_back(make_trajectory_writer(
          f, r.output_dir / (std::string("trajectory") + extension(f)), wopt));
    if (multi(r))
      for (const auto& m : r.modules)
        subsystems.push_back(
            make_trajectory_writer(TrajectoryFormat::kCsv, r.output_dir / (m + ".csv"), wopt));
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
  // What the records are used for (the caller's consumer, e.g. the streaming evaluation,
  // and the hand-over to the writer thread, which waits when the writer is behind) is
  // timed here and left out of filter_seconds.
  double sink_seconds = 0.0;
  Navigator nav(r.manifest, r.modules, nav_opt, [&](int stream, const TrajectoryRecord& rec) {
    const auto t0 = std::chrono::steady_clock::now();
    if (stream == 0 && r.on_record) r.on_record(rec);
    if (pipe) pipe->push(stream, rec);
    sink_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  });

  Progress progress("navigating", total_rows, r.progress);
  // Samples are read in blocks, and only the processing of a block is timed: the
  // filter's own cost, without file reading, at two clock reads per 4096 samples.
  constexpr std::size_t kBlock = 4096;
  std::vector<std::pair<std::size_t, ImuSample>> block(kBlock);
  std::uint64_t n = 0;
  double filter_seconds = 0.0;
  bool more = true, stop = false;
  while (more && !stop) {
    std::size_t count = 0;
    while (count < kBlock && (more = merger.next(block[count].first, block[count].second))) ++count;
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < count; ++k) {
      const ImuSample& s = block[k].second;
      nav.process(static_cast<int>(block[k].first), s);
      if (r.max_duration > 0 && nav.navigating() && s.t - nav.stats().t_start >= r.max_duration) {
        stop = true;
        break;
      }
    }
    filter_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    n += count;
    progress.update(n);
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
  if (pipe) pipe->finish();  // every record written (or the writer's error thrown)
  RunResult result;
  for (auto& w : vehicle) w->commit();
  for (auto& w : subsystems) w->commit();
  if (!r.output_dir.empty()) {
    AtomicTextFile report(r.output_dir / "faults.csv", r.overwrite);
    report.write(fault_report_csv(nav.faults()));
    report.commit();
  }
  result.fault_report = fault_report_text(nav.faults());
  result.fault_events = nav.faults().events();
  result.files = outputs;
  result.stats = nav.stats();
  result.filter_seconds = std::max(0.0, filter_seconds - sink_seconds);
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

}  // namespace wheelins
