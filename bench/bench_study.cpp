// A study job's overhead against its work (issue 17: under 10 % of a 15-minute robot run's
// job time). The study: the default scenario cut to 930 s (30 s static, 15 minutes of
// navigation), robot preset, field profile, one chip per module, single Wheel-INS (the
// cheapest configuration, so the largest share of overhead). Its dataset is simulated once
// per process into a scratch cache; every iteration is then a cache hit, as in a study.
//
//  * BM_StudyJob15MinRobot: what `wheelins study run STUDY --job 0` does in-process: load the
//    study file, resolve the job, check its state, find the dataset, build the run, navigate
//    and evaluate, write jobs/0.json. Counters: job_s (all of it), navigate_s, overhead_ms
//    (everything but navigating) and overhead_pct (of job_s).
//  * BM_StudyProcessStart: the process around it: `wheelins study run STUDY --job 0` on a job
//    that is done (start, study load, state check, exit).
#include <benchmark/benchmark.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>

#include "wheelins/study/job.hpp"
#include "wheelins/study/spec.hpp"

extern char** environ;

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

struct StudySetup {
  fs::path dir, file;
  ~StudySetup() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

const StudySetup& setup() {
  static const std::unique_ptr<StudySetup> s = [] {
    auto x = std::make_unique<StudySetup>();
    x->dir = fs::temp_directory_path() / ("wheelins-bench-study-" + std::to_string(::getpid()));
    fs::create_directories(x->dir);
    x->file = x->dir / "robot15.yaml";
    std::ofstream(x->file)
        << "simulate: {preset: robot, profile: field, chips: 1, duration_s: 930}\n"
           "configurations: [single]\n";
    const study::Study st = study::Study::load(x->file);
    study::run_job(st, st.job(0));  // simulates the dataset into the cache
    return x;
  }();
  return *s;
}

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void BM_StudyJob15MinRobot(benchmark::State& state) {
  const StudySetup& s = setup();
  double job = 0.0, navigate = 0.0, load = 0.0, data = 0.0, setup_s = 0.0, write = 0.0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const study::Study st = study::Study::load(s.file);
    const study::Job j = st.job(0);
    benchmark::DoNotOptimize(study::job_status(st, j));
    load += since(t0);
    const study::JobOutcome r = study::run_job(st, j);
    if (!r.ok || r.timing.generated) state.SkipWithError("the job failed or missed the cache");
    job += since(t0);
    navigate += r.timing.navigate;
    data += r.timing.dataset;
    setup_s += r.timing.setup + r.timing.finish;
    write += r.timing.write;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["job_s"] = job / n;
  state.counters["navigate_s"] = navigate / n;
  state.counters["load_ms"] = 1e3 * load / n;     // study file, job, state
  state.counters["dataset_ms"] = 1e3 * data / n;  // the cache hit
  state.counters["setup_ms"] =
      1e3 * setup_s / n;                         // run configuration, manifest, truth; result text
  state.counters["write_ms"] = 1e3 * write / n;  // jobs/0.json (temporary file, fsync, rename)
  state.counters["overhead_ms"] = 1e3 * (job - navigate) / n;
  state.counters["overhead_pct"] = 100.0 * (job - navigate) / job;
}
BENCHMARK(BM_StudyJob15MinRobot)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

void BM_StudyProcessStart(benchmark::State& state) {
  const StudySetup& s = setup();
  const std::string study = s.file.string();
  std::vector<char*> argv{const_cast<char*>(WHEELINS_BINARY), const_cast<char*>("study"),
                          const_cast<char*>("run"),           const_cast<char*>(study.c_str()),
                          const_cast<char*>("--job"),         const_cast<char*>("0"),
                          const_cast<char*>("--quiet"),       nullptr};
  for (auto _ : state) {
    pid_t pid = 0;
    if (::posix_spawn(&pid, WHEELINS_BINARY, nullptr, nullptr, argv.data(), environ) != 0) {
      state.SkipWithError("cannot start wheelins");
      break;
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) state.SkipWithError("wheelins failed");
  }
}
BENCHMARK(BM_StudyProcessStart)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(20);

}  // namespace
