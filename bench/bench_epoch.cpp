// Whole-epoch and I/O benchmarks: the navigator over a short simulated run held in
// memory (single Wheel-INS, distributed and centralized Triple INS), the position-
// constraint update, and the reader / writer throughput. The data set is simulated
// once per process into a scratch directory (the default field profile, one chip).
//
// Per-epoch figures are the counter us_per_epoch: wall time over the epochs of the
// module driving the output (one epoch = one sample of every IMU in the run).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <vector>

#include "wheelins/filter/ekf_update.hpp"
#include "wheelins/filter/position_constraint.hpp"
#include "wheelins/fusion/navigator.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

struct Dataset {
  fs::path dir;
  Manifest manifest;
  ~Dataset() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

/// 200 s of the default scenario (field profile, one chip per module) on the vehicle of
/// `preset`, simulated into a scratch directory named by `tag`.
std::unique_ptr<Dataset> simulate(const std::string& preset, const std::string& tag) {
  auto ds = std::make_unique<Dataset>();
  ds->dir = fs::temp_directory_path() /
            ("wheelins-bench-" + tag + "-" + std::to_string(::getpid()));
  sim::SimConfig cfg;
  cfg.vehicle = sim::VehicleConfig::preset_named(preset);
  cfg.chips = 1;
  cfg.duration = 200.0;
  cfg.write_ideal = false;
  sim::Simulation(cfg).write(ds->dir, true, false);
  ds->manifest = load_manifest(ds->dir / "manifest.yaml", {});
  return ds;
}

/// The robot of the default scenario, made once.
const Dataset& dataset() {
  static const std::unique_ptr<Dataset> d = simulate("robot", "robot");
  return *d;
}

/// The car with steered front Wheel-IMUs (preset car-steered): four hubs and a body, made once.
const Dataset& steered_car() {
  static const std::unique_ptr<Dataset> d = simulate("car-steered", "car-steered");
  return *d;
}

struct Sample {
  int index;
  ImuSample s;
};

/// The merged, time-ordered samples of `modules`, read once.
std::vector<Sample> samples_of(const Dataset& d, const std::vector<std::string>& modules) {
  std::vector<std::unique_ptr<ImuFileReader>> readers;
  for (const auto& name : modules) {
    const ModuleSpec& spec = *d.manifest.find(name);
    readers.push_back(
        std::make_unique<ImuFileReader>(d.manifest.resolve(spec.file), imu_read_options(spec)));
  }
  ImuMerger merger(stream_pointers(readers));
  std::vector<Sample> out;
  std::size_t k = 0;
  ImuSample s;
  while (merger.next(k, s)) out.push_back({static_cast<int>(k), s});
  return out;
}

void run_navigator(benchmark::State& state, const std::vector<std::string>& modules,
                   bool centralized, bool turn_average = false,
                   const Dataset& data = dataset()) {
  const std::vector<Sample> samples = samples_of(data, modules);
  NavigatorOptions opt;
  opt.fusion.centralized = centralized;
  opt.wheel.turn_average = turn_average;
  opt.output_interval = 1.0;  // the filter, not the output (1 Hz records)
  std::uint64_t epochs = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    Navigator nav(data.manifest, modules, opt, [](int, const TrajectoryRecord&) {});
    for (const Sample& x : samples) nav.process(x.index, x.s);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    epochs += nav.stats().epochs;
    benchmark::DoNotOptimize(nav.stats());
  }
  state.counters["us_per_epoch"] = 1e6 * seconds / static_cast<double>(epochs);
}

void BM_EpochSingleWheelIns(benchmark::State& state) { run_navigator(state, {"left-C1"}, false); }
BENCHMARK(BM_EpochSingleWheelIns)->Unit(benchmark::kMillisecond)->UseRealTime();

// The velocity model kept at every epoch for the update over a whole wheel turn (off by
// default; filter/turn_average.hpp).
void BM_EpochSingleWheelInsTurnAverage(benchmark::State& state) {
  run_navigator(state, {"left-C1"}, false, true);
}
BENCHMARK(BM_EpochSingleWheelInsTurnAverage)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EpochTripleDistributed(benchmark::State& state) {
  run_navigator(state, {"left-C1", "right-C1", "body-C1"}, false);
}
BENCHMARK(BM_EpochTripleDistributed)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EpochTripleCentralized(benchmark::State& state) {
  run_navigator(state, {"left-C1", "right-C1", "body-C1"}, true);
}
BENCHMARK(BM_EpochTripleCentralized)->Unit(benchmark::kMillisecond)->UseRealTime();

// Five IMUs (issue 37): the four hubs of the car with steered front wheels and its body; one
// epoch is five samples.
const std::vector<std::string> kFiveImus{"left-C1", "right-C1", "body-C1", "front-left-C1",
                                         "front-right-C1"};

void BM_EpochFiveImusDistributed(benchmark::State& state) {
  run_navigator(state, kFiveImus, false, false, steered_car());
}
BENCHMARK(BM_EpochFiveImusDistributed)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EpochFiveImusCentralized(benchmark::State& state) {
  run_navigator(state, kFiveImus, true, false, steered_car());
}
BENCHMARK(BM_EpochFiveImusCentralized)->Unit(benchmark::kMillisecond)->UseRealTime();

Mat21 spd_covariance() {
  Mat21 A = Mat21::Random() * 0.01;
  return A * A.transpose() + Mat21::Identity() * 1e-4;
}

void BM_PositionConstraintUpdate(benchmark::State& state) {
  // One subsystem's update of eq. (11): the reference point model (eq. 7) and the fusion.
  ReferencePointInput in;
  in.wheel = true;
  in.C_BtoW = dcm_from_euler(Vec3(0.3, 0.01, 1.2));
  in.p_IinW = Vec3(10.0, -4.0, 0.1);
  in.lever_arm_inB = Vec3(0.015, -0.004, 0.006);
  in.p_inV = Vec3(0.0, -0.165, 0.0);
  in.axle_sign = -1;
  const Mat21 P0 = spd_covariance();
  const Mat3 R = Mat3::Identity() * 0.04;
  const Vec3 reference(10.01, -4.2, 0.09);
  for (auto _ : state) {
    Mat21 P = P0;
    Vec21 dx = Vec21::Zero();
    const ReferencePointModel m = reference_point_model(in);
    benchmark::DoNotOptimize(ekf_update<3>(P, dx, m.H, Vec3(m.r_o - reference), R));
    benchmark::DoNotOptimize(P);
  }
}
BENCHMARK(BM_PositionConstraintUpdate);

void BM_ImuReaderThroughput(benchmark::State& state) {
  const Dataset& d = dataset();
  const ModuleSpec& spec = *d.manifest.find("left-C1");
  std::uint64_t rows = 0;
  for (auto _ : state) {
    ImuFileReader r(d.manifest.resolve(spec.file), imu_read_options(spec));
    ImuSample s;
    while (r.next(s)) ++rows;
    benchmark::DoNotOptimize(s);
  }
  state.counters["rows_per_s"] = benchmark::Counter(static_cast<double>(rows), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ImuReaderThroughput)->Unit(benchmark::kMillisecond)->UseRealTime();

void write_records(benchmark::State& state, TrajectoryFormat format) {
  const fs::path file = dataset().dir / "bench-trajectory.out";
  // Every column non-zero, with realistic magnitudes (zeros would be unrealistically cheap).
  TrajectoryRecord r;
  r.lla = {0.53, 1.99, 21.5};
  r.rpy = Vec3(0.01, -0.02, 1.3);
  r.p_std = Vec3(0.12345, 0.2345, 0.01);
  r.v_std = Vec3(0.0123, 0.0234, 0.00456);
  r.rpy_std = Vec3(0.00123, 0.00234, 0.0145);
  r.bg = Vec3(1.2e-4, -3.4e-4, 5.6e-5);
  r.ba = Vec3(0.0123, -0.0045, 0.031);
  r.sg = Vec3(1.1e-3, -2.2e-4, 3.3e-4);
  r.sa = Vec3(-4.4e-4, 5.5e-4, 6.6e-4);
  r.bg_std = Vec3(2.1e-5, 2.2e-5, 2.3e-5);
  r.ba_std = Vec3(0.0011, 0.0012, 0.0013);
  r.sg_std = Vec3(3.1e-4, 3.2e-4, 3.3e-4);
  r.sa_std = Vec3(4.1e-4, 4.2e-4, 4.3e-4);
  const int n = 20000;
  TrajectoryWriterOptions wopt;
  wopt.overwrite = true;
  for (auto _ : state) {
    auto w = make_trajectory_writer(format, file, wopt);
    for (int i = 0; i < n; ++i) {
      r.t = 100.0 + 0.005 * i;
      r.p_inN = Vec3(0.01 * i, -0.003 * i, 0.0001 * i);
      r.v_inN = Vec3(1.2, -0.3, 0.001 * (i % 7));
      w->write(r);
    }
    w->commit();
  }
  state.counters["records_per_s"] =
      benchmark::Counter(static_cast<double>(n) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}

void BM_TrajectoryWriterCsv(benchmark::State& state) { write_records(state, TrajectoryFormat::kCsv); }
BENCHMARK(BM_TrajectoryWriterCsv)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TrajectoryWriterTum(benchmark::State& state) { write_records(state, TrajectoryFormat::kTum); }
BENCHMARK(BM_TrajectoryWriterTum)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
