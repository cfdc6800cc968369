// Hardening, one class of bad input per test group: numbers out of their physical range,
// NaN entering through a sample, the input checks (static period, format, rate), non-regular
// input files, concurrent and killed writers (all-or-nothing outputs), bounded memory.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "io_test_util.hpp"
#include "wheelins/eval/metrics.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/sim/simulator.hpp"
#include "wheelins/util/interrupt.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define WHEELINS_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define WHEELINS_ASAN 1
#endif
#endif

namespace {
using namespace wheelins;
using iotest::error_of;
namespace fs = std::filesystem;

std::string read_all(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// One small simulated dataset (45 s, one chip per module) for the whole suite.
class Hardening : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("wheelins-hardening-" + std::to_string(::getpid())));
    sim::SimConfig cfg;
    cfg.set_profile("datasheet");
    cfg.chips = 1;
    cfg.duration = 45.0;
    cfg.write_ideal = false;
    sim::Simulation(cfg).write(*dir_ / "data", false, false);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
  }
  /// A copy of the dataset whose manifest text goes through `edit`.
  fs::path variant(const std::string& name, const std::function<void(std::string&)>& edit = {}) {
    const fs::path d = *dir_ / name;
    fs::remove_all(d);
    fs::copy(*dir_ / "data", d, fs::copy_options::recursive);
    if (edit) {
      std::string text = read_all(d / "manifest.yaml");
      edit(text);
      iotest::write_text(d / "manifest.yaml", text);
    }
    return d;
  }
  /// Rewrites one IMU file of a dataset through `edit` on its rows of 7.
  static void edit_rows(const fs::path& file, const std::function<void(std::vector<double>&)>& edit) {
    std::string b = read_all(file);
    std::vector<double> v(b.size() / sizeof(double));
    std::memcpy(v.data(), b.data(), v.size() * sizeof(double));
    edit(v);
    iotest::write_doubles(file, v);
  }
  static RunRequest request(const fs::path& d, const std::string& config, const fs::path& out = {}) {
    RunRequest r;
    r.manifest = load_manifest(d / "manifest.yaml", {});
    r.modules = configuration_modules(r.manifest, config, {});
    r.output_dir = out;
    r.formats = {TrajectoryFormat::kCsv};
    r.progress = false;
    return r;
  }
  static fs::path* dir_;
};
fs::path* Hardening::dir_ = nullptr;

/// Replaces `key` and the value after it (a number, a [...] list, or nothing: a literal key)
/// at its first occurrence by `with`. (Not std::regex: GCC 12 warns falsely inside it under
/// the sanitizers, and the CI builds those with -Werror.)
void replace(std::string& s, const std::string& key, const std::string& with) {
  const std::size_t at = s.find(key);
  ASSERT_NE(at, std::string::npos) << "no '" << key << "' in the text";
  std::size_t end = at + key.size();
  if (end < s.size() && s[end] == '[') {
    end = s.find(']', end);
    ASSERT_NE(end, std::string::npos);
    ++end;
  } else {
    while (end < s.size() && std::string("0123456789.eE+-").find(s[end]) != std::string::npos) ++end;
  }
  s.replace(at, end - at, with);
}

// ------------------------------------------------------------------ numbers and NaN entering

TEST_F(Hardening, ManifestNumbersOutsideTheirRangeAreErrors) {
  const struct {
    const char* pattern;
    const char* with;
    const char* key;
  } cases[] = {
      {"wheel_radius_m: ", "wheel_radius_m: 1e-9", "wheel_radius_m: must be in [0.01, 2]"},
      {"gyro_bias_tau_h: ", "gyro_bias_tau_h: 1e-6", "gyro_bias_tau_h: must be in"},
      {"gyro_arw_deg_sqrt_h: ", "gyro_arw_deg_sqrt_h: 1e300", "gyro_arw_deg_sqrt_h: must be in"},
      {"gravity_m_s2: ", "gravity_m_s2: 4.9", "gravity_m_s2: must be in [9.7, 9.9]"},
      {"rate_hz: ", "rate_hz: 1e9", "rate_hz: must be in"},
      {"h_m: ", "h_m: 1e7", "initial.h_m: must be in"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.with);
    const fs::path d = variant("range", [&](std::string& t) { replace(t, c.pattern, c.with); });
    EXPECT_HAS(error_of([&] { load_manifest(d / "manifest.yaml", {}); }), c.key);
  }
}

TEST_F(Hardening, ZeroFusionWeightsAreErrors) {
  const fs::path cfg = *dir_ / "w.yaml";
  for (const char* w : {"[1, 0, 0]", "[0, 0, 0]", "[1, -1, 1]", "[1, 1e300, 1]"}) {
    SCOPED_TRACE(w);
    iotest::write_text(cfg, std::string("dataset: data/manifest.yaml\nfusion: {weights: ") + w + "}\n");
    EXPECT_HAS(error_of([&] { load_run_config(cfg, {}); }), "fusion.weights[");
  }
  RunRequest r = request(*dir_ / "data", "triple");
  r.nav.fusion.weights = {1.0, 0.0, 0.0};  // the library refuses it too
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "fusion weights");
}

TEST_F(Hardening, SampleBeyondTheSensorRangeIsIsolatedNeverNaN) {
  const fs::path d = variant("spike");
  edit_rows(d / "right-wheel-imu" / "tri_C1_imu.bin", [](std::vector<double>& v) {
    v[7 * 7000 + 5] = 1e300;  // one accelerometer reading
    v[7 * 7100 + 2] = 1e6;    // one gyro reading [rad/s]
  });
  RunRequest r = request(d, "triple", d / "out");
  std::vector<std::string> warnings;
  r.warn = [&](const std::string& w) { warnings.push_back(w); };
  const RunResult res = run_navigation(r);
  EXPECT_HAS(res.fault_report, "2 samples beyond the sensor range or not finite left out");
  ASSERT_FALSE(warnings.empty());
  EXPECT_HAS(warnings.front(), "record 7000");
  const TrajectoryData traj = read_trajectory(d / "out" / "trajectory.csv");
  for (const auto& rec : traj.records) ASSERT_TRUE(rec.p_inN.allFinite() && rec.v_inN.allFinite()) << rec.t;
  EXPECT_HAS(read_all(d / "out" / "faults.csv"), "samples_beyond_range,2");

  r.nav.faults.enabled = false;  // without fault handling: a clear error, nothing written
  r.output_dir = d / "out2";
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "record 7000 (0-based");
  EXPECT_FALSE(fs::exists(d / "out2"));
}

TEST_F(Hardening, NonFiniteSampleIsAFaultLikeOneBeyondTheRange) {
  // One policy for a sample that cannot be: with fault handling it is left out and counted,
  // as one beyond the range; without, the run stops naming the file and the record.
  const fs::path d = variant("nan");
  edit_rows(d / "right-wheel-imu" / "tri_C1_imu.bin", [](std::vector<double>& v) {
    v[7 * 7000 + 5] = std::numeric_limits<double>::quiet_NaN();
    v[7 * 7200 + 2] = std::numeric_limits<double>::infinity();
  });
  RunRequest r = request(d, "triple", d / "out");
  std::vector<std::string> warnings;
  r.warn = [&](const std::string& w) { warnings.push_back(w); };
  const RunResult res = run_navigation(r);
  EXPECT_HAS(res.fault_report, "2 samples beyond the sensor range or not finite left out");
  bool named = false;
  for (const auto& w : warnings) named = named || (w.find("record 7000") != std::string::npos && w.find("not finite") != std::string::npos);
  EXPECT_TRUE(named);
  const TrajectoryData traj = read_trajectory(d / "out" / "trajectory.csv");
  for (const auto& rec : traj.records) ASSERT_TRUE(rec.p_inN.allFinite() && rec.v_inN.allFinite()) << rec.t;
  EXPECT_HAS(read_all(d / "out" / "faults.csv"), "samples_beyond_range,2");
  r.nav.faults.enabled = false;
  r.output_dir = d / "out2";
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "record 7000 (0-based), column 5 (accel_y): value is NaN");
  EXPECT_FALSE(fs::exists(d / "out2"));
}

TEST_F(Hardening, FirstRecordOfAMultiImuRunIsFinite) {
  RunRequest r = request(*dir_ / "data", "triple");
  r.max_duration = 2.0;
  bool first = true;
  r.on_record = [&](const TrajectoryRecord& rec) {
    if (first) {
      EXPECT_TRUE(rec.v_inN.allFinite()) << "the first vehicle record's velocity";
    }
    first = false;
  };
  run_navigation(r);
  EXPECT_FALSE(first);
}

TEST(HardeningEval, EvaluatorRejectsANonFiniteRecordLikeTheFileReader) {
  eval::Evaluator::Sources src;
  src.truth_file = "truth";
  src.traj_file = "memory";
  eval::Evaluator e(earth::LocalFrame({0.5, 2.0, 0.0}), src, {}, false);
  TrajectoryRecord r;
  r.t = 1.0;
  r.lla = {0.5, 2.0, 0.0};
  e.add_trajectory(r);
  r.t = 2.0;
  r.lla.lat = std::nan("");
  EXPECT_HAS(error_of([&] { e.add_trajectory(r); }), "position is not finite");
  EXPECT_HAS(error_of([&] { eval::Evaluator(earth::LocalFrame({0, 0, 0}), src, {1e-9, false, 5.0}, false); }),
             "segment length");
}

TEST_F(Hardening, RunNumbersOutsideTheirRangeAreErrors) {
  RunRequest r = request(*dir_ / "data", "single");
  r.nav.output_interval = 1e9;
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "output interval");
  r = request(*dir_ / "data", "single");
  r.max_duration = std::nan("");
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "duration");
  r = request(*dir_ / "data", "single");
  r.nav.fusion.centralized = true;
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "centralized");
  r = request(*dir_ / "data", "single");
  r.modules = {"left-C1", "left-C1"};
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "listed twice");
}

// A manifest naming an odometer file that is not there (issue 33, "also seen"): the run does
// not read it, but the manifest is wrong and the error names the key and the file.
TEST_F(Hardening, AMissingOdometerFileIsAnErrorNamingTheKey) {
  const fs::path d = variant("no-odometer");
  std::string text = read_all(d / "manifest.yaml");
  const std::size_t at = text.find("\nodometer:");
  ASSERT_NE(at, std::string::npos) << "the simulated manifest names no odometer";
  text.replace(at + 1, text.find('\n', at + 1) - at - 1, "odometer: odo-gone.bin");
  iotest::write_text(d / "manifest.yaml", text);
  RunRequest r = request(d, "single");
  const std::string e = error_of([&] { run_navigation(r); });
  EXPECT_HAS(e, "key 'odometer'");
  EXPECT_HAS(e, "odo-gone.bin' does not exist");
  fs::create_directory(d / "odo-gone.bin");
  r = request(d, "single");
  EXPECT_HAS(error_of([&] { run_navigation(r); }), "is not a regular file");
}

TEST(HardeningSim, SettingsAreCheckedOnceAllAreIn) {
  sim::SimConfig c;
  c.duration = -10.0;
  c.apply_setting("chips=2");  // no longer judges (and blames) the duration
  EXPECT_HAS(error_of([&] { c.validate(); }), "duration_s (--duration)");
  sim::SimConfig s;
  s.speed = 1e-5;
  EXPECT_HAS(error_of([&] { sim::Simulation{s}; }), "speed_m_s (--cruise-speed)");
  s.speed = -1.0;
  EXPECT_HAS(error_of([&] { s.validate(); }), "must be in [0.05, 60]");
}

// `simulate` refuses what `run` would refuse of its dataset (issue 33, "also seen"): a gyro full
// scale below a manifest's range, --static too short for the alignment, a wheel's lever arm
// or a module's position beyond a manifest's limits; at the limits the dataset loads.
TEST(HardeningSim, SimulateRefusesSettingsWhoseDatasetRunRefuses) {
  auto fails = [](const std::string& setting, double static_s = 10.0) {
    sim::SimConfig c;
    c.static_duration = static_s;
    if (!setting.empty()) c.apply_setting(setting);
    return error_of([&] { c.validate(); });
  };
  EXPECT_HAS(fails("errors.gyro_range_deg_s=0.001"), "errors.gyro_range_deg_s");
  EXPECT_HAS(fails("errors.gyro_range_deg_s=0.001"), "gyro_range_dps");
  EXPECT_HAS(fails("", 0.0), "static_s (--static)");
  EXPECT_HAS(fails("", 0.0), "at least 10");
  EXPECT_HAS(fails("vehicle.left-wheel.lever_arm_m=[5, 0, 0]"), "vehicle.left-wheel.lever_arm_m");
  EXPECT_HAS(fails("vehicle.body.position_m=[0, 0, 25]"), "vehicle.body.position_m");
  // Without the saturation effect the full scale is not written: any value is harmless.
  sim::SimConfig ideal;
  ideal.set_profile("ideal");
  ideal.apply_setting("errors.gyro_range_deg_s=0.001");
  EXPECT_NO_THROW(ideal.validate());

  // Just inside every limit: the dataset's manifest loads.
  iotest::ScratchDir dir;
  sim::SimConfig c;
  c.duration = 2.0;
  c.static_duration = 10.0 / c.rate_hz;
  c.apply_setting("errors.gyro_range_deg_s=10");
  c.apply_setting("vehicle.left-wheel.lever_arm_m=[0.98, 0, 0]");
  c.apply_setting("vehicle.body.position_m=[19.9, 0, 0]");
  ASSERT_NO_THROW(c.validate());
  sim::Simulation{c}.write(dir / "ds", false, false);
  EXPECT_NO_THROW(load_manifest(dir / "ds" / "manifest.yaml"));
}

// ------------------------------------------------------------------------- the input checks

TEST_F(Hardening, StaticPeriodFormatAndRateAreCheckedFromTheData) {
  {
    const fs::path d = variant("moving", [](std::string& t) {
      replace(t, "static_period_s: ", "static_period_s: [100040, 100044]");
    });
    EXPECT_HAS(error_of([&] { run_navigation(request(d, "single")); }), "deg/s on average in the static period");
  }
  {
    const fs::path d = variant("as-increments", [](std::string& t) { replace(t, "format: rate", "format: increment"); });
    EXPECT_HAS(error_of([&] { run_navigation(request(d, "single")); }), "the file holds rates");
  }
  {
    const fs::path d = variant("rate", [](std::string& t) { replace(t, "rate_hz: 200", "rate_hz: 100"); });
    EXPECT_HAS(error_of([&] { run_navigation(request(d, "single")); }), "i.e. 200 Hz, but the manifest declares");
  }
  {
    const fs::path d = variant("slow", [](std::string& t) { replace(t, "rate_hz: 200", "rate_hz: 20"); });
    EXPECT_HAS(error_of([&] { run_navigation(request(d, "single")); }), "faults.max_gap_s");
  }
}

// --------------------------------------------------------------------- non-regular input files

TEST(HardeningFiles, NonRegularInputsAreRefusedClearly) {
  iotest::ScratchDir dir;
  const fs::path fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_symlink("loop-b", dir / "loop-a");
  fs::create_symlink("loop-a", dir / "loop-b");
  fs::create_symlink("nowhere", dir / "dangling");
  EXPECT_HAS(error_of([&] { ImuFileReader r(fifo); }), "is a FIFO");
  EXPECT_HAS(error_of([&] { ImuFileReader r("/dev/zero"); }), "is a character device");
  EXPECT_HAS(error_of([&] { read_truth("/dev/null"); }), "is a character device");
  EXPECT_HAS(error_of([&] { load_manifest(dir / "loop-a", {}); }), "too many levels of symbolic links");
  EXPECT_HAS(error_of([&] { load_manifest(dir / "dangling", {}); }), "symbolic link to a file that does not exist");
  EXPECT_HAS(error_of([&] { load_run_config("/dev/zero", {}); }), "is a character device");
  ImuReadOptions text;
  text.layout = FileLayout::kText;
  iotest::write_text(dir / "zeros.txt", std::string(1 << 20, '\0'));
  EXPECT_HAS(error_of([&] { ImuFileReader r(dir / "zeros.txt", text); }), "a line longer than");
}

TEST(HardeningFiles, YamlDepthSizeAndWarningsAreBounded) {
  iotest::ScratchDir dir;
  iotest::write_text(dir / "flow.yaml", "a: " + std::string(500, '[') + std::string(500, ']') + "\n");
  EXPECT_HAS(error_of([&] { load_run_config(dir / "flow.yaml", {}); }), "nested deeper than");
  std::string block = "format: wheelins-manifest-1\n";
  for (int k = 0; k < 500; ++k) block += std::string(2 * static_cast<std::size_t>(k), ' ') + "k" + std::to_string(k) + ":\n";
  iotest::write_text(dir / "block.yaml", block);
  EXPECT_HAS(error_of([&] { load_manifest(dir / "block.yaml", {}); }), "nested deeper than");
  iotest::write_text(dir / "big.yaml", "dataset: x\n" + std::string(5u << 20, '#'));
  EXPECT_HAS(error_of([&] { load_run_config(dir / "big.yaml", {}); }), "at most 4 MiB");
  std::string many = "dataset: m.yaml\n";
  for (int k = 0; k < 1000; ++k) many += "unknown_" + std::to_string(k) + ": 1\n";
  iotest::write_text(dir / "many.yaml", many);
  int warnings = 0;
  load_run_config(dir / "many.yaml", [&](const std::string&) { ++warnings; });
  EXPECT_EQ(warnings, io_detail::kMaxKeyWarnings + 1);  // 20 and one count of the rest
}

// ------------------------------------------------------------- all-or-nothing, concurrency

TEST(HardeningOutput, SecondWriterFailsAndNothingForeignIsReplaced) {
  iotest::ScratchDir dir;
  const fs::path target = dir / "out";
  {
    OutputDir a(target, {});
    EXPECT_HAS(error_of([&] { OutputDir b(target, {}); }), "another wheelins command is writing");
    iotest::write_text(a.staging() / "trajectory.csv", "one\n");
    EXPECT_FALSE(fs::exists(target / "trajectory.csv"));  // nothing visible before commit
    a.commit();
  }
  EXPECT_EQ(read_all(target / "trajectory.csv"), "one\n");
  EXPECT_HAS(error_of([&] { OutputDir c(target, {}); }), "already holds results");
  OutputDirOptions force;
  force.overwrite = true;
  {
    OutputDir d(target, force);
    iotest::write_text(d.staging() / "trajectory.csv", "two\n");
    d.commit();
  }
  EXPECT_EQ(read_all(target / "trajectory.csv"), "two\n");
  iotest::write_text(dir / "mine" / "notes.txt", "keep\n");
  EXPECT_HAS(error_of([&] { OutputDir e(dir / "mine", force); }), "did not write");
  OutputDirOptions with_input = force;
  with_input.inputs = {target / "trajectory.csv"};
  EXPECT_HAS(error_of([&] { OutputDir f(target, with_input); }), "an input of this command");
  OutputDirOptions dataset = force;
  dataset.kind = "dataset";
  EXPECT_HAS(error_of([&] { OutputDir g(target, dataset); }), "holds wheelins results (not a dataset)");
  iotest::write_text(dir / "file", "x");
  EXPECT_HAS(error_of([&] { OutputDir h(dir / "file" / "out", {}); }), "cannot create the directory");
}

TEST(HardeningOutput, AWriterThatThrowsMidwayLeavesTheEarlierOutputWhole) {
  iotest::ScratchDir dir;
  const fs::path target = dir / "out";
  {
    OutputDir a(target, {});
    iotest::write_text(a.staging() / "trajectory.csv", "old\n");
    iotest::write_text(a.staging() / "trajectory.tum", "old\n");
    a.commit();
  }
  OutputDirOptions force;
  force.overwrite = true;
  try {
    OutputDir b(target, force);
    iotest::write_text(b.staging() / "trajectory.csv", "new\n");
    throw std::runtime_error("killed midway");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(read_all(target / "trajectory.csv"), "old\n");
  EXPECT_EQ(read_all(target / "trajectory.tum"), "old\n");
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir.path())) entries += e.path().filename() != "out";
  EXPECT_EQ(entries, 0) << "a staging directory was left behind";
  // A staging directory of a writer that is gone (killed) is removed by the next writer.
  fs::create_directories(dir / ".out.partial-999999999-abcdef");
  { OutputDir c(target, force); }
  EXPECT_FALSE(fs::exists(dir / ".out.partial-999999999-abcdef"));
}

TEST_F(Hardening, RunKilledMidwayKeepsTheEarlierResults) {
  const fs::path out = *dir_ / "killed";
  RunRequest r = request(*dir_ / "data", "dual-wheel", out);
  r.max_duration = 5.0;
  run_navigation(r);
  const std::string before = read_all(out / "trajectory.csv");
  r.overwrite = true;
  r.max_duration = 0.0;
  int n = 0;
  r.on_record = [&](const TrajectoryRecord&) {
    if (++n == 1000) throw std::runtime_error("killed midway");
  };
  EXPECT_THROW(run_navigation(r), std::runtime_error);
  EXPECT_EQ(read_all(out / "trajectory.csv"), before);
  EXPECT_TRUE(fs::exists(out / "left-C1.csv"));
  r.on_record = [&](const TrajectoryRecord&) { request_interrupt(); };  // Ctrl-C
  EXPECT_THROW(run_navigation(r), Interrupted);
  clear_interrupt();
  EXPECT_EQ(read_all(out / "trajectory.csv"), before);
  for (const auto& e : fs::directory_iterator(*dir_))
    EXPECT_EQ(e.path().filename().string().find(".killed.partial"), std::string::npos) << e.path();
}

// --------------------------------------------------------------------------- bounded memory

#ifndef WHEELINS_ASAN
/// Runs `f` in a child process limited to `mb` of address space; true if it ended with an
/// InputError (not a crash and not bad_alloc).
bool input_error_within(std::size_t mb, const std::function<void()>& f) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    rlimit lim{mb << 20, mb << 20};
    ::setrlimit(RLIMIT_AS, &lim);
    int code = 3;
    try {
      f();
      code = 1;
    } catch (const InputError&) {
      code = 0;
    } catch (...) {
      code = 2;
    }
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}
#endif

TEST(HardeningMemory, HugeAndEndlessInputsStayWithinAFewHundredMegabytes) {
#ifdef WHEELINS_ASAN
  GTEST_SKIP() << "address-space limits do not mix with AddressSanitizer's shadow memory";
#else
  iotest::ScratchDir dir;
  iotest::write_text(dir / "zeros.txt", "");
  fs::resize_file(dir / "zeros.txt", std::uintmax_t{600} << 20);  // 600 MB of zeros (sparse), no newline
  std::string keys = "format: wheelins-manifest-1\n";
  for (int k = 0; k < 1000000; ++k) keys += "u" + std::to_string(k) + ": 1\n";
  iotest::write_text(dir / "keys.yaml", keys);
  ImuReadOptions text;
  text.layout = FileLayout::kText;
  EXPECT_TRUE(input_error_within(512, [&] {
    ImuFileReader r(dir / "zeros.txt", text);
  }));
  EXPECT_TRUE(input_error_within(512, [&] { load_manifest("/dev/zero", {}); }));
  EXPECT_TRUE(input_error_within(512, [&] { load_manifest(dir / "keys.yaml", {}); }));
  EXPECT_TRUE(input_error_within(512, [&] {
    eval::Evaluator::Sources src;
    eval::Evaluator e(earth::LocalFrame({0, 0, 0}), src, {1e-9, false, 5.0}, false);
  }));
#endif
}

}  // namespace
