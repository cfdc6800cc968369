// The live stream (run/live_stream.hpp): text lines of five IMUs (the car with steered front
// Wheel-IMUs, 200 Hz each) parsed, put back in order, navigated and published, as
// `wheelins live` does them, from lines held in memory (no reading, no pacing).
//
// Counters: us_per_line, the mean cost of a line; latency_median_us and latency_p99_us, over
// the lines after which a state was published (every 0.1 s of data), the time from the line's
// hand-over to the state written (to /dev/null) and flushed.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "wheelins/io/manifest.hpp"
#include "wheelins/run/live_stream.hpp"
#include "wheelins/sim/simulator.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kModules{"left-C1", "right-C1", "body-C1", "front-left-C1", "front-right-C1"};

struct LiveData {
  fs::path dir;
  std::vector<std::string> lines;
  LiveData() {
    dir = fs::temp_directory_path() / ("wheelins-bench-live-" + std::to_string(::getpid()));
    sim::SimConfig cfg;
    cfg.vehicle = sim::VehicleConfig::preset_named("car-steered");
    cfg.chips = 1;
    cfg.duration = 120.0;
    cfg.write_ideal = false;
    sim::Simulation(cfg).write(dir, false, false);
    const Manifest m = load_manifest(dir / "manifest.yaml", {});
    std::vector<std::tuple<double, std::size_t, std::vector<double>>> rows;
    for (std::size_t i = 0; i < kModules.size(); ++i) {
      std::ifstream f(m.resolve(m.find(kModules[i])->file), std::ios::binary);
      std::stringstream ss;
      ss << f.rdbuf();
      const std::string bytes = ss.str();
      std::vector<double> v(bytes.size() / sizeof(double));
      std::memcpy(v.data(), bytes.data(), v.size() * sizeof(double));
      for (std::size_t k = 0; k + 7 <= v.size(); k += 7)
        rows.emplace_back(v[k], i, std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(k),
                                                       v.begin() + static_cast<std::ptrdiff_t>(k + 7)));
    }
    std::sort(rows.begin(), rows.end());
    char buf[512];
    for (const auto& [t, i, v] : rows) {
      std::snprintf(buf, sizeof buf, "%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", kModules[i].c_str(), v[0],
                    v[1], v[2], v[3], v[4], v[5], v[6]);
      lines.emplace_back(buf);
    }
  }
  ~LiveData() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

const LiveData& live_data() {
  static const LiveData d;
  return d;
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void BM_LiveStreamFiveImus(benchmark::State& state) {
  const LiveData& d = live_data();
  std::FILE* sink = std::fopen("/dev/null", "w");
  double seconds = 0.0, median = 0.0, p99 = 0.0;
  std::uint64_t lines = 0;
  for (auto _ : state) {
    RunRequest req;
    req.manifest = load_manifest(d.dir / "manifest.yaml", {});
    req.modules = kModules;
    req.calibration = CalibrationMode::kManifest;
    req.progress = false;
    PushSession session(req, 60.0, "bench");
    LiveStream stream(session, LiveStreamOptions{}, sink, sink);
    const double t0 = now_seconds();
    for (const std::string& l : d.lines) stream.line(l, now_seconds());
    stream.end();
    seconds += now_seconds() - t0;
    lines += d.lines.size();
    latency_percentiles(stream.stats().latency, median, p99);
    benchmark::DoNotOptimize(session.finish());
  }
  std::fclose(sink);
  state.counters["us_per_line"] = 1e6 * seconds / static_cast<double>(lines);
  state.counters["latency_median_us"] = 1e6 * median;
  state.counters["latency_p99_us"] = 1e6 * p99;
}
BENCHMARK(BM_LiveStreamFiveImus)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
