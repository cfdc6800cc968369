// Studies (src/wheelins/study, `wheelins study`): the statistics, the study file, the dataset
// cache under concurrency, atomic results, and the same report however the jobs ran (one
// command, shuffled --job calls, GNU parallel, a Slurm array task by task).
#include <gtest/gtest.h>
#include <signal.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io_test_util.hpp"
#include "wheelins/study/dataset.hpp"
#include "wheelins/study/job.hpp"
#include "wheelins/study/report.hpp"
#include "wheelins/study/spec.hpp"
#include "wheelins/study/stats.hpp"

using namespace wheelins;
using namespace wheelins::study;
using wheelins::iotest::ScratchDir;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void put(const fs::path& f, const std::string& text) {
  fs::create_directories(f.parent_path());
  std::ofstream(f, std::ios::binary) << text;
}

struct Cmd {
  int code;
  std::string out, err;
};

/// Runs a shell command line in `dir`, capturing its output.
Cmd shell(const std::string& line, const fs::path& dir) {
  const fs::path out = dir / ".cmd-out", err = dir / ".cmd-err";
  const std::string cmd =
      "cd '" + dir.string() + "' && " + line + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  Cmd c{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
  fs::remove(out);
  fs::remove(err);
  return c;
}
std::string bin() { return std::string("'") + WHEELINS_BINARY + "'"; }
std::string script(const char* name) {
  return std::string("'") + WHEELINS_SOURCE_DIR + "/scripts/" + name + "'";
}

/// A small study: 2 seeds x 3 configurations on 60 s of simulated car data (one chip per
/// module): 200 m, so the drift rate has two segments; the whole study takes about a second.
const char* kSmall =
    "name: small\n"
    "simulate:\n"
    "  preset: car\n"
    "  chips: 1\n"
    "  static_s: 10\n"
    "  duration_s: 60\n"
    "seeds: [1, 2]\n"
    "configurations: [single, body-wheel, triple]\n";

/// The report files that depend only on the results (timing.csv does not).
const char* kReportFiles[] = {"report.md",
                              "summary.csv",
                              "differences.csv",
                              "jobs.csv",
                              "report.json",
                              "plots/drift.gp",
                              "plots/heading.gp",
                              "plots/data/drift_summary.csv",
                              "plots/data/drift_jobs.csv",
                              "plots/data/heading_summary.csv"};

/// A job file without its timing and with one name for the cache directory (the rest must
/// not depend on how or where the job ran).
std::string result_part(std::string json) {
  const auto a = json.find("\"timing\":");
  const auto b = json.find("\"status\":");
  if (a != std::string::npos && b != std::string::npos) json = json.substr(0, a) + json.substr(b);
  for (std::size_t p; (p = json.find("/parcache/")) != std::string::npos;)
    json.replace(p, 10, "/cache/");
  return json;
}

}  // namespace

// --- Statistics ------------------------------------------------------------------------

TEST(StudyStats, StudentTQuantilesMatchTables) {
  // Reference values: R qt() (to the digits shown).
  EXPECT_NEAR(student_t_quantile(0.975, 1), 12.706204736, 1e-8);
  EXPECT_NEAR(student_t_quantile(0.975, 4), 2.776445105, 1e-8);
  EXPECT_NEAR(student_t_quantile(0.975, 19), 2.093024054, 1e-8);
  EXPECT_NEAR(student_t_quantile(0.995, 10), 3.169272667, 1e-8);
  EXPECT_NEAR(student_t_quantile(0.975, 1e7), 1.959964, 1e-5);
  EXPECT_NEAR(student_t_quantile(0.025, 19), -2.093024054, 1e-8);
  EXPECT_NEAR(student_t_cdf(2.093024054, 19), 0.975, 1e-9);
  EXPECT_NEAR(incomplete_beta(0.5, 2, 3), 0.6875, 1e-12);
  EXPECT_NEAR(incomplete_beta(0.2, 0.5, 0.5), 2.0 / M_PI * std::asin(std::sqrt(0.2)), 1e-12);
  EXPECT_TRUE(std::isnan(student_t_quantile(1.0, 3)));
}

TEST(StudyStats, SummaryTIntervalAndBootstrap) {
  const Summary s = summarize({1, 2, 3, 4, std::nan("")});
  EXPECT_EQ(s.n, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_NEAR(s.sd, std::sqrt(5.0 / 3.0), 1e-12);
  const double half = 3.182446305 * std::sqrt(5.0 / 3.0) / 2.0;
  EXPECT_NEAR(s.lo, 2.5 - half, 1e-8);
  EXPECT_NEAR(s.hi, 2.5 + half, 1e-8);
  const Summary one = summarize({7.0});
  EXPECT_EQ(one.n, 1u);
  EXPECT_TRUE(std::isnan(one.sd) && std::isnan(one.lo));
  EXPECT_EQ(summarize({}).n, 0u);

  IntervalOptions b;
  b.method = IntervalMethod::kBootstrap;
  std::vector<double> v;
  for (int i = 0; i < 30; ++i) v.push_back(std::sin(i) + 0.1 * i);
  const Summary x = summarize(v, b), y = summarize(v, b);
  EXPECT_EQ(x.lo, y.lo);  // a fixed seed: the same interval every time
  EXPECT_EQ(x.hi, y.hi);
  EXPECT_LT(x.lo, x.mean);
  EXPECT_GT(x.hi, x.mean);
  // For 30 values the bootstrap interval of the mean is close to the t interval.
  const Summary t = summarize(v);
  EXPECT_NEAR(x.hi - x.lo, t.hi - t.lo, 0.2 * (t.hi - t.lo));
}

// --- The study file --------------------------------------------------------------------

TEST(StudySpec, AxesMultiplyInOrderAndSettingsResolve) {
  ScratchDir d;
  put(d / "s.yaml",
      "simulate: {chips: 1, duration_s: 60, errors.gyro_sf_ppm: 2000}\n"
      "run: {filter: {velocity_gate: 4}}\n"
      "sweep:\n"
      "  simulate.preset: [robot, car]\n"
      "  simulate.wheel_noise: [0.3, 2]\n"
      "  noise:\n"
      "    default: {}\n"
      "    tight: {run.filter.wheel_velocity_std_m_s: [0.01, 0.01, 0.01], "
      "simulate.errors.gyro_sf_ppm: 5000}\n"
      "seeds: 1..3\n"
      "configurations:\n"
      "  - single\n"
      "  - {name: gated-triple, configuration: triple, run.filter.velocity_gate: 9}\n"
      "  - centralized\n");
  const Study s = Study::load(d / "s.yaml");
  ASSERT_EQ(s.axes().size(), 5u);
  EXPECT_EQ(s.job_count(), 2u * 2 * 2 * 3 * 3);
  EXPECT_EQ(s.configurations(),
            (std::vector<std::string>{"single", "gated-triple", "centralized"}));
  EXPECT_EQ(s.results_dir(), fs::absolute(d / "s").lexically_normal());
  EXPECT_EQ(s.cache_dir(), s.results_dir() / "datasets");

  // The configuration is innermost, the first sweep axis outermost.
  const Job j0 = s.job(0), j1 = s.job(1), jlast = s.job(s.job_count() - 1);
  EXPECT_EQ(j0.labels, (std::vector<std::string>{"robot", "0.3", "default", "1", "single"}));
  EXPECT_EQ(j1.labels, (std::vector<std::string>{"robot", "0.3", "default", "1", "gated-triple"}));
  EXPECT_EQ(jlast.labels, (std::vector<std::string>{"car", "2", "tight", "3", "centralized"}));
  EXPECT_EQ(j0.dataset.canonical, j1.dataset.canonical);  // same data for every configuration
  EXPECT_NE(j0.key, j1.key);

  // Simulator settings: the options' names, the profile's scale factor overridden, the seed.
  ASSERT_TRUE(jlast.dataset.sim);
  const sim::SimConfig& c = *jlast.dataset.sim;
  EXPECT_EQ(c.vehicle.preset, "car");
  EXPECT_EQ(c.chips, 1);
  EXPECT_EQ(c.seed, 3u);
  EXPECT_TRUE(c.on("wheel_noise"));
  EXPECT_NEAR(c.errors.wheel_accel_noise, 2.0 / 60.0, 1e-15);
  EXPECT_NEAR(c.errors.gyro_sf, 5000e-6, 1e-15);  // the variant overrides the study's 2000
  EXPECT_NEAR(j0.dataset.sim->errors.gyro_sf, 2000e-6, 1e-15);
  EXPECT_FALSE(c.write_ideal);
  EXPECT_NE(jlast.dataset.cache_name.find("car-field-seed3-"), std::string::npos);

  // Run settings reach the code that reads run configurations.
  const RunConfig r0 = load_run_yaml(j0.run_yaml, "/x/manifest.yaml", "test");
  EXPECT_EQ(r0.configuration, "single");
  EXPECT_EQ(r0.nav.wheel.gate, 4.0);
  EXPECT_DOUBLE_EQ(r0.nav.output_interval, 0.05);
  const RunConfig r1 = load_run_yaml(j1.run_yaml, "/x/manifest.yaml", "test");
  EXPECT_EQ(r1.configuration, "triple");
  EXPECT_EQ(r1.nav.wheel.gate, 9.0);
  const RunConfig rl = load_run_yaml(jlast.run_yaml, "/x/manifest.yaml", "test");
  EXPECT_EQ(rl.configuration, "triple");
  EXPECT_TRUE(rl.nav.fusion.centralized);
  EXPECT_DOUBLE_EQ(rl.nav.wheel.velocity_std.x(), 0.01);
  EXPECT_EQ(s.check_all().size(), s.job_count());
  // Every pair of three configurations is compared.
  EXPECT_EQ(s.compare().size(), 3u);
}

TEST(StudySpec, AnyRunConfigKeyWorksThroughTheRunConfigReader) {
  ScratchDir d;
  put(d / "s.yaml",
      "simulate: {chips: 1}\n"
      "sweep:\n"
      "  run.faults.window: [30]\n"
      "  run.filter.initial_std.heading_deg: [0.5]\n"
      "  run.fusion.weights: [[1, 2, 1]]\n"
      "configurations: [{name: t, configuration: triple, chip: C1}]\n");
  const Study s = Study::load(d / "s.yaml");
  const Job j = s.job(0);
  const RunConfig r = load_run_yaml(j.run_yaml, "/x/manifest.yaml", "test");
  EXPECT_EQ(r.nav.faults.window, 30);
  EXPECT_NEAR(r.nav.wheel.init.heading, 0.5 * kDeg, 1e-15);
  EXPECT_EQ(r.nav.fusion.weights, (std::vector<double>{1, 2, 1}));
  EXPECT_EQ(r.chips, (std::vector<std::string>{"C1", "C1", "C1"}));
}

TEST(StudySpec, MistakesNameTheFileAndKey) {
  ScratchDir d;
  auto err = [&](const std::string& text) {
    put(d / "bad.yaml", text);
    return iotest::error_of([&] { Study::load(d / "bad.yaml").check_all(); });
  };
  std::string e = err("simulate: {chips: 1}\nsweeps: {simulate.seed: [1]}\n");
  EXPECT_HAS(e, "bad.yaml");
  EXPECT_HAS(e, "sweeps: unknown key");
  EXPECT_HAS(e, "did you mean 'sweep'");
  // A misspelt run-configuration key fails before any job runs, with the closest key.
  e = err("simulate: {chips: 1}\nsweep: {run.filter.velocity_gat: [1, 2]}\n");
  EXPECT_HAS(e, "bad.yaml");
  EXPECT_HAS(e, "filter.velocity_gat: unknown key");
  EXPECT_HAS(e, "velocity_gate");
  e = err("simulate: {chips: 1, errors.gyro_sf_pm: 3}\n");
  EXPECT_HAS(e, "gyro_sf_pm");
  e = err("simulate: {chips: 1}\nconfigurations: [single, tripel]\n");
  EXPECT_HAS(e, "unknown configuration 'tripel'");
  EXPECT_HAS(e, "did you mean 'triple'");
  e =
      err("simulate: {chips: 1}\nconfigurations: [{name: x, configuration: triple, simulate.seed: "
          "3}]\n");
  EXPECT_HAS(e, "cannot change the data");
  e = err("dataset: /nowhere/manifest.yaml\nsimulate: {chips: 1}\n");
  EXPECT_HAS(e, "both a dataset");
  e = err("run: {filter: {velocity_gate: 3}}\n");
  EXPECT_HAS(e, "no data");
  e = err("simulate: {chips: 1}\nsweep: {wheel_noise: [1, 2]}\n");
  EXPECT_HAS(e, "simulate.wheel_noise");
  e = err("simulate: {chips: 1}\nsweep: {simulate.seed: [1, 1]}\n");
  EXPECT_HAS(e, "appears twice");
  e = err("simulate: {chips: 1}\nrun: {output: {dir: x}}\n");
  EXPECT_HAS(e, "writes no trajectories");
  e = err("simulate: {chips: 1}\nseeds: 3..1\n");
  EXPECT_HAS(e, "empty");
}

TEST(StudySpec, CanonicalTextIsTheSettingsNotTheirOrder) {
  ScratchDir d;
  put(d / "a.yaml",
      "simulate: {chips: 1, profile: datasheet, seed: 4}\nrun: {filter: {velocity_gate: 3}, "
      "duration_s: 50}\n");
  put(d / "b.yaml",
      "simulate: {seed: 4, profile: datasheet, chips: 1}\nrun: {duration_s: 50, "
      "filter.velocity_gate: 3}\n");
  put(d / "c.yaml",
      "simulate: {seed: 4, profile: datasheet, chips: 1}\nrun: {duration_s: 50, "
      "filter.velocity_gate: 4}\n");
  const Job a = Study::load(d / "a.yaml").job(0), b = Study::load(d / "b.yaml").job(0),
            c = Study::load(d / "c.yaml").job(0);
  EXPECT_EQ(a.canonical, b.canonical);
  EXPECT_EQ(a.key, b.key);
  EXPECT_EQ(a.dataset.canonical, c.dataset.canonical);
  EXPECT_NE(a.key, c.key);
  EXPECT_NE(a.dataset.canonical.find("profile: datasheet"), std::string::npos);
}

TEST(StudySpec, ReferencesToTheDataSettings) {
  ScratchDir d;
  put(d / "s.yaml",
      "simulate: {chips: 1, profile: field}\n"
      "run: {filter.velocity_gate: \"${seed}*2\"}\n"
      "sweep:\n"
      "  simulate.wheel_noise: [0.5, 2]\n"
      "  noise:\n"
      "    none: {manifest.modules.*.noise: null}\n"
      "    x3:\n"
      "      manifest.modules.kind=wheel.noise.acc_vrw_m_s_sqrt_h: ${simulate.wheel_noise}*3\n"
      "      manifest.modules.*.noise.gyro_sf_ppm: ${simulate.errors.gyro_sf_ppm}/3\n"
      "seeds: [4]\n");
  const Study s = Study::load(d / "s.yaml");
  ASSERT_EQ(s.job_count(), 4u);
  const Job j = s.job(3);  // wheel noise 2, x3
  EXPECT_HAS(j.dataset.manifest_edits, "modules.kind=wheel.noise.acc_vrw_m_s_sqrt_h\": 6");
  EXPECT_HAS(j.dataset.manifest_edits,
             "modules.*.noise.gyro_sf_ppm\": 1000");  // the field profile's 3000 / 3
  EXPECT_EQ(load_run_yaml(j.run_yaml, "/x/manifest.yaml", "t").nav.wheel.gate, 8.0);
  EXPECT_EQ(s.job(0).dataset.canonical,
            s.job(1).dataset.canonical);  // edits do not change the data
  EXPECT_EQ(s.data_siblings(3), (std::vector<std::size_t>{2, 3}));
  put(d / "bad.yaml",
      "simulate: {chips: 1}\nmanifest:\n  modules.*.noise.gyro_sf_ppm: ${simulate.errors.nope}\n");
  EXPECT_HAS(iotest::error_of([&] { Study::load(d / "bad.yaml").job(0); }),
             "${simulate.errors.nope}: no such simulator setting");
  put(d / "bad.yaml", "simulate: {chips: 1}\nrun:\n  filter.velocity_gate: x${seed}\n");
  EXPECT_HAS(iotest::error_of([&] { Study::load(d / "bad.yaml").job(0); }),
             "a reference is a whole value");
}

// --- Manifest edits and the dataset cache ----------------------------------------------

TEST(StudyDataset, ManifestEdits) {
  const std::string m =
      "format: wheelins-manifest-1\ntruth: GINS.bin\nmodules:\n"
      "  - {name: left-C1, kind: wheel, file: a.bin, noise: {gyro_arw_deg_sqrt_h: 0.24, "
      "acc_vrw_m_s_sqrt_h: 0.3}}\n"
      "  - {name: body-C1, kind: body, file: b.bin, noise: {gyro_arw_deg_sqrt_h: 0.24}}\n";
  const YAML::Node none = YAML::Load(edit_manifest(m, "- {modules.*.noise: null}\n", {}, "m"));
  EXPECT_FALSE(none["modules"][0]["noise"]);
  EXPECT_FALSE(none["modules"][1]["noise"]);
  const YAML::Node one = YAML::Load(
      edit_manifest(m, "- {modules.left-C1.noise.acc_vrw_m_s_sqrt_h: 2}\n", "/data", "m"));
  EXPECT_EQ(one["modules"][0]["noise"]["acc_vrw_m_s_sqrt_h"].as<double>(), 2.0);
  EXPECT_EQ(one["modules"][0]["noise"]["gyro_arw_deg_sqrt_h"].as<double>(), 0.24);
  EXPECT_FALSE(one["modules"][1]["noise"]["acc_vrw_m_s_sqrt_h"]);
  EXPECT_EQ(one["truth"].as<std::string>(), "/data/GINS.bin");  // paths made absolute
  EXPECT_EQ(one["modules"][1]["file"].as<std::string>(), "/data/b.bin");
  const YAML::Node wheels =
      YAML::Load(edit_manifest(m, "- {modules.kind=wheel.noise.acc_vrw_m_s_sqrt_h: 2}\n", {}, "m"));
  EXPECT_EQ(wheels["modules"][0]["noise"]["acc_vrw_m_s_sqrt_h"].as<double>(), 2.0);
  EXPECT_FALSE(wheels["modules"][1]["noise"]["acc_vrw_m_s_sqrt_h"]);
  EXPECT_HAS(iotest::error_of(
                 [&] { edit_manifest(m, "- {modules.left-C9.noise.x: 1}\n", {}, "'m.yaml'"); }),
             "manifest.modules.left-C9.noise.x matches nothing");
}

TEST(StudyDataset, ConcurrentPreparationGeneratesOnce) {
  ScratchDir d;
  put(d / "s.yaml",
      "simulate: {preset: car, chips: 1, static_s: 5, duration_s: 8}\n"
      "manifest: {modules.*.noise: null}\n");
  const Study s = Study::load(d / "s.yaml");
  const Job j = s.job(0);
  // A generator killed earlier left its temporary directory behind.
  fs::create_directories(s.cache_dir() / (".tmp." + j.dataset.cache_name + ".deadhost-1-0"));
  constexpr int kThreads = 6;
  std::vector<PreparedDataset> got(kThreads);
  std::atomic<int> ready{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i)
    threads.emplace_back([&, i] {
      ++ready;
      while (ready < kThreads) std::this_thread::yield();
      got[static_cast<std::size_t>(i)] = prepare_dataset(j.dataset, s.cache_dir());
    });
  for (auto& t : threads) t.join();
  int generated = 0;
  for (const auto& g : got) {
    generated += g.generated;
    EXPECT_EQ(g.manifest, got[0].manifest);
  }
  EXPECT_EQ(generated, 1);
  const fs::path dir = s.cache_dir() / j.dataset.cache_name;
  EXPECT_EQ(got[0].manifest.parent_path(), dir);
  EXPECT_EQ(slurp(dir / "settings.txt"), j.dataset.canonical);
  EXPECT_EQ(slurp(got[0].manifest).find("noise:"), std::string::npos);  // the edit applied
  for (const auto& e : fs::directory_iterator(s.cache_dir()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp.", 0), std::string::npos) << e.path();
  // A second preparation finds it.
  EXPECT_FALSE(prepare_dataset(j.dataset, s.cache_dir()).generated);
}

// --- Jobs, results and reports ----------------------------------------------------------

TEST(StudyRun, FailingResultWriterLeavesNoResult) {
  ScratchDir d;
  put(d / "s.yaml", kSmall);
  const Study s = Study::load(d / "s.yaml");
  const Job j = s.job(2);
  JobOptions o;
  std::size_t written = 0;
  o.write_chunk = [&](int fd, std::string_view chunk) {
    // Half of the result reaches the disk, then the writer fails (a full disk, a kill).
    const std::size_t half = chunk.size() / 2;
    ASSERT_EQ(::write(fd, chunk.data(), half), static_cast<ssize_t>(half));
    written += half;
    throw std::runtime_error("disk full (simulated)");
  };
  const JobOutcome r = run_job(s, j, o);
  EXPECT_FALSE(r.ok);
  EXPECT_GT(written, 100u);
  EXPECT_HAS(r.error, "disk full (simulated)");
  EXPECT_FALSE(fs::exists(s.jobs_dir() / "2.json"));
  for (const auto& e : fs::directory_iterator(s.jobs_dir()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos)
        << "left behind: " << e.path();
  EXPECT_EQ(job_status(s, j).state, JobState::kFailed);
  EXPECT_HAS(job_status(s, j).detail, "disk full");

  // A half-written result file (as a writer without the temporary file would leave) is
  // not read as complete either.
  std::string full;
  ASSERT_TRUE(run_job(s, j).ok);
  ASSERT_TRUE(read_file(s.jobs_dir() / "2.json", full));
  EXPECT_FALSE(fs::exists(s.jobs_dir() / "2.failed.json"));
  put(s.jobs_dir() / "2.json", full.substr(0, full.size() / 2));
  EXPECT_EQ(job_status(s, j).state, JobState::kUnreadable);
  std::string error;
  EXPECT_FALSE(read_job_record(s.jobs_dir() / "2.json", error));
  ReportOptions ro;
  ro.plots = false;
  const Report rep = write_report(s, ro);
  EXPECT_EQ(rep.done, 0u);
  EXPECT_EQ(rep.not_done.size(), 6u);
  EXPECT_HAS(rep.markdown, "## Jobs not in this report");
  EXPECT_HAS(rep.markdown, "| 2 | unreadable |");
  EXPECT_HAS(rep.markdown, "| 0 | missing |");
}

TEST(StudyRun, KilledJobLeavesNoCompleteResultAndResumes) {
  ScratchDir d;
  // Long enough (car, 150 s) to be killed while generating or navigating.
  put(d / "s.yaml",
      "simulate: {preset: car, chips: 1, static_s: 10, duration_s: 150}\n"
      "configurations: [triple]\n");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl(WHEELINS_BINARY, WHEELINS_BINARY, "study", "run", (d / "s.yaml").c_str(), "--job", "0",
            "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the job finished before the kill; make it longer";
  const Study s = Study::load(d / "s.yaml");
  EXPECT_FALSE(fs::exists(s.jobs_dir() / "0.json"));
  EXPECT_EQ(job_status(s, s.job(0)).state, JobState::kMissing);
  // The cache holds no dataset that is not complete (a killed generator's copy is temporary).
  const fs::path data = s.cache_dir() / s.job(0).dataset.cache_name;
  if (fs::exists(data)) {
    EXPECT_EQ(slurp(data / "settings.txt"), s.job(0).dataset.canonical);
  }

  const Cmd again = shell(bin() + " study run s.yaml --job 0", d.path());
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(job_status(s, s.job(0)).state, JobState::kDone);
  for (const auto& e : fs::directory_iterator(s.cache_dir()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp.", 0), std::string::npos) << e.path();
  const Cmd done = shell(bin() + " study run s.yaml --job 0", d.path());
  EXPECT_EQ(done.code, 0);
  EXPECT_HAS(done.out, "already done");
}

TEST(StudyRun, FailedJobIsReported) {
  ScratchDir d;
  put(d / "s.yaml", std::string(kSmall).substr(0, std::string(kSmall).find("seeds")) +
                        "seeds: [1]\nconfigurations: [single, {name: bad, configuration: triple, "
                        "chips: [C1, C1, C9]}]\n");
  const Cmd r = shell(bin() + " study run s.yaml", d.path());
  EXPECT_EQ(r.code, 1);
  EXPECT_HAS(r.err, "job 1 failed");
  EXPECT_HAS(r.err, "C9");
  const std::string md = slurp(d / "s" / "report.md");
  EXPECT_HAS(md, "**1 not done**");
  EXPECT_HAS(md, "| 1 | failed | 1 | bad |");
  EXPECT_HAS(md, "C9");
  EXPECT_HAS(slurp(d / "s" / "jobs.csv"), "1,1,bad,failed,");
  const Cmd strict = shell(bin() + " study report s.yaml --strict --no-plots", d.path());
  EXPECT_EQ(strict.code, 3);
  EXPECT_HAS(strict.out, "job 1 (1 | bad): failed");
}

TEST(StudyRun, SameReportHoweverTheJobsRan) {
  ScratchDir d;
  put(d / "s.yaml", kSmall);
  const Study s = Study::load(d / "s.yaml");
  ASSERT_EQ(s.job_count(), 6u);

  // 1. One command: every job on all cores, then the report.
  const Cmd one = shell(bin() + " study run s.yaml --results one --cache cache -j 2", d.path());
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_HAS(one.out, "6 done, 0 failed");

  // 2. Separate --job calls in shuffled order (one of them a range), then the report.
  std::vector<std::string> order{"4", "1", "5", "0", "2-3"};
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  for (const auto& k : order) {
    const Cmd c =
        shell(bin() + " study run s.yaml --results shuffled --cache cache --job " + k, d.path());
    ASSERT_EQ(c.code, 0) << c.err;
  }
  const Cmd rep = shell(bin() + " study report s.yaml --results shuffled --cache cache", d.path());
  ASSERT_EQ(rep.code, 0) << rep.err;
  EXPECT_HAS(rep.out, "6 of 6 jobs in the report");

  // 3. GNU parallel, through the ssh-login path to this machine, with its own cache: three
  //    processes want each dataset at once.
  bool have_parallel = std::system("command -v parallel >/dev/null 2>&1") == 0;
  if (have_parallel) {
    const Cmd p = shell(script("study-parallel.sh") + " --wheelins " + bin() +
                            " -j 3 --sshlogin 3/: --results par --cache parcache s.yaml",
                        d.path());
    ASSERT_EQ(p.code, 0) << p.out << p.err;
  }

  // 4. The Slurm array script, task by task in reverse order.
  for (int task = 5; task >= 0; --task) {
    const Cmd c =
        shell("SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " WHEELINS=" + bin() + " bash " +
                  script("study.sbatch") + " s.yaml --results slurm --cache cache --quiet",
              d.path());
    ASSERT_EQ(c.code, 0) << c.out << c.err;
  }
  ASSERT_EQ(shell(bin() + " study report s.yaml --results slurm --cache cache -q", d.path()).code,
            0);

  std::vector<std::string> ways{"shuffled", "slurm"};
  if (have_parallel) ways.push_back("par");
  for (const char* f : kReportFiles) {
    const std::string ref = slurp(d / "one" / f);
    ASSERT_FALSE(ref.empty()) << f;
    for (const auto& w : ways) EXPECT_EQ(slurp(d / w / f), ref) << w << "/" << f << " differs";
  }
  for (int k = 0; k < 6; ++k) {
    const std::string ref = result_part(slurp(d / "one" / "jobs" / (std::to_string(k) + ".json")));
    for (const auto& w : ways)
      EXPECT_EQ(result_part(slurp(d / w / "jobs" / (std::to_string(k) + ".json"))), ref)
          << w << " job " << k;
  }
  // The report has the numbers: every cell filled, intervals, paired differences, plots.
  const std::string md = slurp(d / "one" / "report.md");
  EXPECT_HAS(md, "6 in this report.");
  EXPECT_HAS(md, "Student t interval");
  EXPECT_HAS(md, "| triple - single |");
  EXPECT_EQ(md.find("| - |"), std::string::npos) << md;
  EXPECT_EQ(md.find("not done"), std::string::npos);
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_TRUE(fs::exists(d / "one" / "plots" / "drift.png"));
    EXPECT_TRUE(fs::exists(d / "one" / "plots" / "heading.png"));
  }
  // A done job is not run again; a changed setting makes the results stale, and they are kept.
  const Cmd resume = shell(bin() + " study run s.yaml --results one --cache cache", d.path());
  EXPECT_EQ(resume.code, 0);
  EXPECT_HAS(resume.out, "all 6 jobs already done");
  std::string changed = kSmall;
  changed.replace(changed.find("duration_s: 60"), 14, "duration_s: 61");
  put(d / "s.yaml", changed);
  const Cmd plan = shell(bin() + " study plan s.yaml --results one --cache cache", d.path());
  ASSERT_EQ(plan.code, 0) << plan.err;
  EXPECT_HAS(plan.out, "0 done, 0 failed, 6 stale");
  ASSERT_EQ(shell(bin() + " study run s.yaml --results one --cache cache --job 0", d.path()).code,
            0);
  EXPECT_EQ(
      std::distance(fs::directory_iterator(d / "one" / "jobs" / "stale"), fs::directory_iterator{}),
      1);
}

TEST(StudyRun, ExperimentIsABuiltInStudy) {
  ScratchDir d;
  ASSERT_EQ(
      shell(bin() + " simulate --out data --preset car --chips 2 --static 10 --duration 40 -q",
            d.path())
          .code,
      0);
  // One command, as before.
  const Cmd one = shell(
      bin() + " experiment data -o one --only single,triple,centralized --no-plots -q", d.path());
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_HAS(one.out, "## Table 4: single Wheel-INS");
  EXPECT_TRUE(fs::exists(d / "one" / "study.yaml"));
  // Sharded: the study file, jobs in reverse order, then the study's report.
  const Cmd prep = shell(
      bin() + " experiment data -o sharded --only single,triple,centralized --prepare", d.path());
  ASSERT_EQ(prep.code, 0) << prep.err;
  const Cmd count = shell(bin() + " study plan sharded/study.yaml --count", d.path());
  const int n = std::stoi(count.out);
  EXPECT_EQ(n, 4 + 4 + 4);  // 4 single, 4 triple, 4 centralized with two chips per module
  for (int k = n - 1; k >= 0; --k)
    ASSERT_EQ(
        shell(bin() + " study run sharded/study.yaml -q --job " + std::to_string(k), d.path()).code,
        0);
  const Cmd rep = shell(bin() + " study report sharded/study.yaml --no-plots -q", d.path());
  ASSERT_EQ(rep.code, 0) << rep.err;
  // The tables but the timing (Table 8, the wall time) are the same.
  auto tables = [](std::string md) {
    md = md.substr(0, md.find("## Table 8"));
    const auto a = md.find("runs in "), b = md.find(" s.", a);
    return md.erase(a, b - a);
  };
  EXPECT_EQ(tables(slurp(d / "sharded" / "experiment.md")),
            tables(slurp(d / "one" / "experiment.md")));
  auto metrics = [](const std::string& csv) {  // runs.csv without the timing columns
    std::string out;
    std::istringstream in(csv);
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> f;
      std::stringstream ls(line);
      for (std::string x; std::getline(ls, x, ',');) f.push_back(x);
      for (std::size_t i = 0; i < f.size(); ++i)
        if (i < 12 || i == 16) out += f[i] + ",";
      out += "\n";
    }
    return out;
  };
  EXPECT_EQ(metrics(slurp(d / "sharded" / "runs.csv")), metrics(slurp(d / "one" / "runs.csv")));
  // The one command's output appears as a whole: the study, its jobs, the tables.
  EXPECT_TRUE(fs::exists(d / "one" / "jobs" / "0.json"));
  EXPECT_TRUE(fs::exists(d / "one" / ".wheelins"));
  // Existing results are refused without --force, as before; another experiment's study too.
  const Cmd again =
      shell(bin() + " experiment data -o one --only single,triple,centralized --no-plots -q", d.path());
  EXPECT_EQ(again.code, 2);
  EXPECT_HAS(again.err, "already holds experiment");
  const Cmd other = shell(bin() + " experiment data -o sharded --only single --prepare", d.path());
  EXPECT_EQ(other.code, 2);
  EXPECT_HAS(other.err, "holds the study of another experiment");
  const Cmd full = shell(bin() + " experiment data -o one --prepare", d.path());
  EXPECT_EQ(full.code, 2);
  EXPECT_HAS(full.err, "holds the finished output of `wheelins experiment`");
  fs::create_directories(d / "mine");
  put(d / "mine" / "notes.txt", "the user's file");
  const Cmd foreign = shell(bin() + " experiment data -o mine --prepare", d.path());
  EXPECT_EQ(foreign.code, 2);
  EXPECT_HAS(foreign.err, "is not empty");
}

TEST(StudyRun, InterruptedRunKeepsFinishedJobsAndResumes) {
  ScratchDir d;
  std::string text = kSmall;
  text.replace(text.find("seeds: [1, 2]"), 13, "seeds: 1..5");
  put(d / "s.yaml", text);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::execl(WHEELINS_BINARY, WHEELINS_BINARY, "study", "run", (d / "s.yaml").c_str(), "-j", "1", "--no-report",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const Study s = Study::load(d / "s.yaml");
  // Wait for a first finished job, then Ctrl-C.
  for (int i = 0; i < 400 && !fs::exists(s.jobs_dir() / "0.json"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 130) << "the study finished before the interrupt";
  std::size_t done = 0;
  for (std::size_t k = 0; k < s.job_count(); ++k) {
    const JobState st = job_status(s, s.job(k)).state;
    EXPECT_TRUE(st == JobState::kDone || st == JobState::kMissing) << "job " << k << ": " << job_state_name(st);
    done += st == JobState::kDone;
  }
  EXPECT_GE(done, 1u);
  EXPECT_LT(done, s.job_count());
  for (const auto& e : fs::directory_iterator(s.jobs_dir()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  const Cmd resume = shell(bin() + " study run s.yaml --no-report", d.path());
  ASSERT_EQ(resume.code, 0) << resume.err;
  EXPECT_HAS(resume.out, "(" + std::to_string(done) + " were done before)");
}

TEST(StudyRun, DatasetsDeletedWhenEveryJobOnThemIsDone) {
  ScratchDir d;
  put(d / "s.yaml",
      "keep_datasets: false\nsimulate: {preset: car, chips: 1, static_s: 5, duration_s: 12}\n"
      "seeds: [1, 2]\nconfigurations: [single, triple]\n");
  const Study s = Study::load(d / "s.yaml");
  const fs::path seed1 = s.cache_dir() / s.job(0).dataset.cache_name;
  ASSERT_EQ(shell(bin() + " study run s.yaml --job 0 -q", d.path()).code, 0);
  EXPECT_TRUE(fs::exists(seed1));  // job 1 still needs it
  ASSERT_EQ(shell(bin() + " study run s.yaml -q --no-report", d.path()).code, 0);
  EXPECT_FALSE(fs::exists(seed1));
  EXPECT_FALSE(fs::exists(s.cache_dir() / s.job(2).dataset.cache_name));
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(job_status(s, s.job(k)).state, JobState::kDone);
}

TEST(StudyRun, JobListParsing) {
  EXPECT_EQ(parse_job_list("3", 10), (std::vector<std::size_t>{3}));
  EXPECT_EQ(parse_job_list("7-9,1,8", 10), (std::vector<std::size_t>{1, 7, 8, 9}));
  EXPECT_HAS(iotest::error_of([] { parse_job_list("10", 10); }), "job 10 does not exist");
  EXPECT_HAS(iotest::error_of([] { parse_job_list("x", 10); }), "not a job number");
  EXPECT_HAS(iotest::error_of([] { parse_job_list("5-2", 10); }), "empty");
}

TEST(StudyRun, ExampleStudiesAreValid) {
  // studies/*.yaml: every axis value resolves and every run configuration reads.
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(WHEELINS_SOURCE_DIR) / "studies")) {
    if (e.path().extension() != ".yaml") continue;
    ++files;
    LoadOptions o;
    ScratchDir d;
    o.results_dir = d.path();  // nothing is written next to the examples
    const Study s = Study::load(e.path(), o);
    std::set<std::string> checked;
    const std::size_t n = s.job_count(), step = std::max<std::size_t>(1, n / 97);
    for (std::size_t k = 0; k < n; k += step) {
      const Job j = s.job(k);
      if (checked.insert(j.run_yaml).second) check_run_yaml(j.run_yaml, e.path().string());
    }
    EXPECT_GT(n, 100u) << e.path();
  }
  EXPECT_GE(files, 2);
}
