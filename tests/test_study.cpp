// Studies (src/wheelins/study): the statistics, the study file and its jobs (axes, settings,
// references to the data's settings, mistakes named), the dataset cache and manifest edits,
// also under concurrency. Running jobs, results and reports: test_study_run.cpp.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "io_test_util.hpp"
#include "study_test_util.hpp"
#include "wheelins/study/dataset.hpp"
#include "wheelins/study/spec.hpp"
#include "wheelins/study/stats.hpp"

using namespace wheelins;
using namespace wheelins::study;
using namespace wheelins::studytest;
using wheelins::iotest::ScratchDir;
namespace fs = std::filesystem;

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
