// Google Benchmark: a real recording's way through wheelins, as a user takes it -- a
// two-minute, five-IMU car recording as vendor CSV tables (Xsens DOT exports at 120 Hz, two
// wheels with two IMUs each and one on the body, their clocks apart) and a GNSS track as
// CSV (5 Hz, its time column in tenths of a second): `wheelins import` (tables converted,
// modules surveyed, clocks fitted, manifest drafted), `wheelins calibrate --reference`
// (installation and reference calibration), and `wheelins run -c triple` (all formats,
// evaluated). The recording is simulated (a car, field profile) once per process in the
// setup; each iteration imports into a fresh directory.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/run/calibration.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/reference_calibration.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/run/table_dataset.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

struct Recording {
  fs::path dir, tables, gnss;
  Recording() {
    dir = fs::temp_directory_path() / ("wheelins-bench-recording-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    sim::SimConfig cfg;
    cfg.vehicle = sim::VehicleConfig::preset_named("car");
    cfg.chips = 2;
    cfg.rate_hz = 120.0;
    cfg.static_duration = 15.0;
    cfg.duration = 135.0;
    cfg.write_ideal = false;
    cfg.errors.gyro_range = 4000.0 * kDeg;
    sim::Simulation(cfg).write(dir / "sim", false, false);
    const Manifest m = load_manifest(dir / "sim" / "manifest.yaml", WarningSink{});
    tables = dir / "tables";
    fs::create_directories(tables);
    int written = 0;
    for (const ModuleSpec& s : m.modules) {
      if (s.kind == ModuleKind::kBody && s.chip != "C1") continue;  // five IMUs: 2 + 2 wheels, 1 body
      write_dot(m.resolve(s.file), tables / (s.name + ".csv"), written == 1 ? 133.0 : 0.0);
      ++written;
    }
    // The GNSS track: 5 Hz, time in tenths of a second.
    const TruthData truth = read_truth(m.resolve(*m.truth_file));
    gnss = dir / "GNSS.csv";
    std::FILE* out = std::fopen(gnss.c_str(), "wb");
    std::fprintf(out, "Timestamp,Lat_GNSS,Long_GNSS,Height_GNSS\n");
    double next = -1e300;
    for (const TruthRecord& r : truth.records) {
      if (r.t < next) continue;
      next = r.t + 0.2;
      std::fprintf(out, "%.1f,%.9f,%.9f,%.3f\n", (r.t - truth.records.front().t) * 10.0, r.lla.lat / kDeg, r.lla.lon / kDeg,
                   r.lla.h);
    }
    std::fclose(out);
  }
  ~Recording() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  /// An IMU file as a DOT export: SampleTimeFine in microseconds (shifted by `clock_s`),
  /// deg/s, m/s^2.
  static void write_dot(const fs::path& in, const fs::path& out_file, double clock_s) {
    ImuReadOptions o;
    o.rate_hz = 120.0;
    ImuFileReader r(in, o);
    std::FILE* out = std::fopen(out_file.c_str(), "wb");
    std::fprintf(out, "sep=,\nPacketCounter,SampleTimeFine,Euler_X,Euler_Y,Euler_Z,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z,\n");
    ImuSample s;
    std::uint64_t k = 0;
    while (r.next(s)) {
      const ImuRow& row = r.row();
      std::fprintf(out, "%llu, %llu, 0, 0, 0, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, \n", static_cast<unsigned long long>(k++),
                   static_cast<unsigned long long>(std::llround((row.t - 99000.0 + clock_s) * 1e6)), row.accel.x(), row.accel.y(),
                   row.accel.z(), row.gyro.x() / kDeg, row.gyro.y() / kDeg, row.gyro.z() / kDeg);
    }
    std::fclose(out);
  }
};

const Recording& recording() {
  static const Recording r;
  return r;
}

fs::path import_once(const Recording& rec, int iteration) {
  TableDatasetOptions o;
  o.inputs = {rec.tables};
  o.out_dir = rec.dir / ("dataset-" + std::to_string(iteration));
  fs::remove_all(o.out_dir);
  o.preset = "xsens-dot";
  o.truth = rec.gnss;
  o.warn = [](const std::string&) {};
  return import_table_dataset(o).manifest_file;
}

Manifest calibrate_once(const fs::path& manifest_file) {
  const Manifest m = load_manifest(manifest_file, WarningSink{});
  std::vector<std::string> modules;
  for (const auto& s : m.modules) modules.push_back(s.name);
  const InstallationCalibration cal = calibrate_installation(m, modules, InstallationCalibrationOptions{}, true, false);
  ReferenceCalibrationOptions ro;
  const ReferenceCalibration ref = calibrate_against_reference(m, modules, cal, ro, WarningSink{});
  return apply_reference_calibration(apply_calibration(m, cal), ref);
}

void run_once(const Manifest& m, const fs::path& out) {
  RunRequest r;
  r.manifest = m;
  r.modules = configuration_modules(m, "triple", {});
  r.output_dir = out;
  r.overwrite = true;
  r.progress = false;
  r.warn = [](const std::string&) {};
  run_navigation(r);
}

void BM_RecordingImport(benchmark::State& state) {
  const Recording& rec = recording();
  int i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(import_once(rec, i++));
}
BENCHMARK(BM_RecordingImport)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

void BM_RecordingCalibrate(benchmark::State& state) {
  const Recording& rec = recording();
  const fs::path manifest = import_once(rec, 1000);
  for (auto _ : state) benchmark::DoNotOptimize(calibrate_once(manifest));
}
BENCHMARK(BM_RecordingCalibrate)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

void BM_RecordingRunTriple(benchmark::State& state) {
  const Recording& rec = recording();
  const Manifest m = calibrate_once(import_once(rec, 1001));
  for (auto _ : state) run_once(m, rec.dir / "run");
}
BENCHMARK(BM_RecordingRunTriple)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

/// The three together: what `import`, `calibrate --reference` and `run` cost a user.
void BM_RecordingImportCalibrateRun(benchmark::State& state) {
  const Recording& rec = recording();
  int i = 2000;
  for (auto _ : state) run_once(calibrate_once(import_once(rec, i++)), rec.dir / "run-all");
}
BENCHMARK(BM_RecordingImportCalibrateRun)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

}  // namespace
