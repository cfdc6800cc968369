// Hardening, third round (issue 33): the one YAML loading path (limits on aliases, depth and
// size; conversions naming key and line) and the one rule for output paths (never an input,
// never outside the output directory, --force replaces only what wheelins wrote, all or
// nothing), checked through the library and the command line.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "ros/bag_writers.hpp"
#include "wheelins/io/ros/import.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/io/yaml_reader.hpp"
#include "wheelins/run/run_config.hpp"
#include "wheelins/sim/config.hpp"
#include "wheelins/study/files.hpp"
#include "wheelins/study/spec.hpp"

using namespace wheelins;
using iotest::error_of;
namespace fs = std::filesystem;

namespace {

/// Nine levels of ten nested aliases under `head` (10^9 values once expanded; 1 KB of text).
std::string billion_laughs(const std::string& head) {
  std::string s = head + "l0: &l0 [\"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\", \"lol\"]\n";
  for (int k = 1; k <= 8; ++k) {
    const std::string prev = "*l" + std::to_string(k - 1);
    s += "l" + std::to_string(k) + ": &l" + std::to_string(k) + " [";
    for (int i = 0; i < 10; ++i) s += (i ? ", " : "") + prev;
    s += "]\n";
  }
  return s;
}

const char* kManifestHead =
    "format: wheelins-manifest-1\n"
    "initial: {lat_deg: 30.5, lon_deg: 114.25, h_m: 20, heading_deg: 90}\n";

std::string manifest_with(const std::string& modules) { return kManifestHead + std::string("modules:\n") + modules; }

std::string wheel(const std::string& name, const std::string& file) {
  return "  - name: \"" + name + "\"\n    kind: wheel\n    file: " + file + "\n    wheel_radius_m: 0.097\n";
}

struct Cmd {
  int code;
  std::string err;
};
Cmd cli(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / ".stderr";
  const std::string line = "cd '" + dir.string() + "' && '" + WHEELINS_BINARY + "' " + args + " >/dev/null 2>'" +
                           err.string() + "'";
  const int status = std::system(line.c_str());
  Cmd c{WIFEXITED(status) ? WEXITSTATUS(status) : -1, iotest::read_text_file(err)};
  fs::remove(err);
  return c;
}

}  // namespace

// ------------------------------------------------------------------ one YAML loading path

TEST(HardeningYaml, NestedAliasesAreRefusedAtOnceByEveryLoader) {
  iotest::ScratchDir dir;
  iotest::write_text(dir / "m.yaml", billion_laughs(kManifestHead));
  iotest::write_text(dir / "r.yaml", billion_laughs("dataset: m.yaml\n"));
  iotest::write_text(dir / "s.yaml", billion_laughs("name: laughs\n"));
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_HAS(error_of([&] { load_manifest(dir / "m.yaml", {}); }), "aliases (*name) repeat more than");
  EXPECT_HAS(error_of([&] { load_run_config(dir / "r.yaml", {}); }), "r.yaml': line");
  EXPECT_HAS(error_of([&] { study::Study::load(dir / "s.yaml"); }), "s.yaml': line");
  sim::SimConfig c;
  EXPECT_HAS(error_of([&] { c.apply_setting(std::string("errors=") +
                                            "[&a [1,1,1,1,1,1,1,1,1,1], &b [*a,*a,*a,*a,*a,*a,*a,*a,*a,*a], "
                                            "&c [*b,*b,*b,*b,*b,*b,*b,*b,*b,*b], &d [*c,*c,*c,*c,*c,*c,*c,*c,*c,*c], "
                                            "&e [*d,*d,*d,*d,*d,*d,*d,*d,*d,*d], &f [*e,*e,*e,*e,*e,*e,*e,*e,*e,*e]]"); }),
             "--set 'errors=");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 1.0);
}

TEST(HardeningYaml, AnAliasInsideItsOwnNodeIsACycleAndAFewAliasesAreFine) {
  EXPECT_HAS(error_of([] { parse_yaml("a: &x {b: *x}\n", "'c.yaml'", "study"); }), "'c.yaml': line 1: an alias");
  const YAML::Node n = parse_yaml("base: &b {x: 1, y: [1, 2, 3]}\none: *b\ntwo: *b\n", "'ok.yaml'", "study");
  EXPECT_EQ(n["two"]["y"].size(), 3u);
  EXPECT_HAS(error_of([] { parse_yaml(std::string("a: 1\0", 5), "'n.yaml'", "manifest"); }), "NUL bytes");
}

TEST(HardeningYaml, AStudyValueOfTheWrongTypeNamesTheKeyAndLine) {
  iotest::ScratchDir dir;
  iotest::write_text(dir / "s.yaml",
                     "name: typed\n"
                     "simulate:\n"
                     "  duration_s: 60\n"
                     "seeds: [1, abc]\n");
  const study::Study s = study::Study::load(dir / "s.yaml");
  const std::string e = error_of([&] { (void)s.job(1); });
  EXPECT_HAS(e, "s.yaml");
  EXPECT_HAS(e, "seed (set by seeds (line 4)): expected a whole number");
  EXPECT_HAS(e, "got 'abc'");
  EXPECT_EQ(e.find("bad conversion"), std::string::npos) << e;
  sim::SimConfig c;
  EXPECT_HAS(error_of([&] { c.apply_setting("laps=two"); }), "laps: expected a whole number");
  EXPECT_HAS(error_of([&] { c.apply_setting("stops=maybe"); }), "stops: expected true or false, got 'maybe'");
}

TEST(HardeningYaml, ExperimentOnlyIsCheckedUnderTheOptionsName) {
  EXPECT_HAS(error_of([] { study::check_experiment_only({"triple", "quadruple"}, "--only"); }),
             "--only: unknown configuration 'quadruple'");
  iotest::ScratchDir dir;
  const Cmd c = cli("experiment nowhere --only quadruple -o out", dir.path());
  EXPECT_EQ(c.code, 2);
  EXPECT_HAS(c.err, "--only: unknown configuration 'quadruple'");
  EXPECT_EQ(c.err.find("study.yaml"), std::string::npos) << c.err;
}

// ------------------------------------------------------------------ module names, once

TEST(HardeningPaths, ModuleNamesAreCheckedWhereTheManifestIsRead) {
  iotest::ScratchDir dir;
  auto load_error = [&](const std::string& modules) {
    iotest::write_text(dir / "m.yaml", manifest_with(modules));
    return error_of([&] { load_manifest(dir / "m.yaml", {}); });
  };
  EXPECT_HAS(load_error(wheel("../../escaped", "a.bin")), "modules[0].name: module name '../../escaped'");
  EXPECT_HAS(load_error(wheel("left,right", "a.bin")), "modules[0].name: module name 'left,right'");
  for (const char* reserved : {"trajectory", "faults", "weights"})
    EXPECT_HAS(load_error(wheel(reserved, "a.bin")), "the name of a run's own output");
  iotest::write_text(dir / "a.bin", "");
  const std::string same = load_error(wheel("left", "a.bin") + wheel("right", "./a.bin"));
  EXPECT_HAS(same, "modules[1].file: module 'right' reads the same file as module 'left'");
}

// ------------------------------------------------------------------ output files

TEST(HardeningPaths, AnOutputIsNeverAnInputNorAnotherOutput) {
  iotest::ScratchDir dir;
  iotest::write_text(dir / "truth.txt", "t\n");
  const fs::path other_name = dir.path() / "sub" / ".." / "truth.txt";
  fs::create_directories(dir / "sub");
  EXPECT_HAS(error_of([&] { check_output_files({{other_name, "--json"}}, {{dir / "truth.txt", "the truth (--truth)"}}, true); }),
             "--json '");
  EXPECT_HAS(error_of([&] { check_output_files({{other_name, "--json"}}, {{dir / "truth.txt", "the truth (--truth)"}}, true); }),
             "is the truth (--truth) '");
  EXPECT_HAS(error_of([&] { check_output_files({{dir / "f", "--json"}, {dir / "f", "--series"}}, {}, true); }),
             "--series '");
  EXPECT_HAS(error_of([&] { check_output_files({{dir / "f", "--json"}, {dir / "f", "--series"}}, {}, true); }),
             "the same file as --json");
  EXPECT_HAS(error_of([&] { check_output_files({{"", "--report"}}, {}, true); }), "--report: an empty file name");
  EXPECT_NO_THROW(check_output_files({{dir / "new.json", "--json"}}, {{dir / "truth.txt", "the truth"}}, false));
}

TEST(HardeningPaths, ForceReplacesOnlyWhatWheelinsWroteAndNamesWhatItKeeps) {
  iotest::ScratchDir dir;
  const fs::path target = dir / "out";
  {
    OutputDir a(target, {});
    iotest::write_text(a.staging() / "trajectory.csv", "one\n");
    a.commit();
  }
  iotest::write_text(target / "notes.txt", "mine\n");
  iotest::write_text(target / "later-run" / "trajectory.csv", "my other results\n");
  OutputDirOptions force;
  force.overwrite = true;
  std::vector<std::string> notices;
  force.notice = [&](const std::string& m) { notices.push_back(m); };
  {
    OutputDir b(target, force);
    iotest::write_text(b.staging() / "trajectory.csv", "two\n");
    b.commit();
    EXPECT_EQ(b.kept().size(), 2u);
  }
  EXPECT_EQ(iotest::read_text_file(target / "trajectory.csv"), "two\n");
  EXPECT_EQ(iotest::read_text_file(target / "notes.txt"), "mine\n");
  EXPECT_EQ(iotest::read_text_file(target / "later-run" / "trajectory.csv"), "my other results\n");
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_HAS(notices[0], "kept what wheelins did not write there: 'later-run', 'notes.txt'");
  // A file of the user's that the new output would write under the same name: refused, and
  // nothing changes.
  iotest::write_text(target / "left.csv", "my table\n");
  try {
    OutputDir c(target, force);
    iotest::write_text(c.staging() / "trajectory.csv", "three\n");
    iotest::write_text(c.staging() / "left.csv", "results\n");
    EXPECT_HAS(error_of([&] { c.commit(); }), "'left.csv', which wheelins did not write there");
  } catch (const InputError& e) {
    ADD_FAILURE() << e.what();
  }
  EXPECT_EQ(iotest::read_text_file(target / "left.csv"), "my table\n");
  EXPECT_EQ(iotest::read_text_file(target / "trajectory.csv"), "two\n");
  EXPECT_EQ(iotest::read_text_file(target / "notes.txt"), "mine\n");
}

TEST(HardeningPaths, AnOutputDirectoryThatIsALinkIsWrittenThroughAndStaysALink) {
  iotest::ScratchDir dir;
  fs::create_directories(dir / "real");
  fs::create_directory_symlink(dir / "real", dir / "link");
  for (int pass = 0; pass < 2; ++pass) {
    OutputDirOptions o;
    o.overwrite = pass == 1;
    OutputDir a(dir / "link", o);
    iotest::write_text(a.staging() / "trajectory.csv", std::to_string(pass) + "\n");
    a.commit();
  }
  EXPECT_TRUE(fs::is_symlink(dir / "link"));
  EXPECT_EQ(iotest::read_text_file(dir / "real" / "trajectory.csv"), "1\n");
  fs::create_directory_symlink(dir / "nowhere", dir / "dangling");
  EXPECT_HAS(error_of([&] { OutputDir b(dir / "dangling", {}); }), "a symbolic link to");
}

TEST(HardeningPaths, StaleTemporariesOfAKilledWriterAreRemovedAndNothingElse) {
  iotest::ScratchDir dir;
  iotest::write_text(dir / "left_imu.bin.partial-999999999-0", "x");
  iotest::write_text(dir / "manifest.yaml.partial-999999999-3", "x");
  const std::string alive = "right_imu.bin.partial-" + std::to_string(::getpid()) + "-0";
  iotest::write_text(dir / alive, "x");
  iotest::write_text(dir / "notes.partial-draft", "mine");
  iotest::write_text(dir / "a.partial-999999999-0x", "mine");
  const auto removed = io_detail::sweep_stale_partials(dir.path());
  EXPECT_EQ(removed.size(), 2u);
  EXPECT_FALSE(fs::exists(dir / "left_imu.bin.partial-999999999-0"));
  EXPECT_TRUE(fs::exists(dir / alive));
  EXPECT_TRUE(fs::exists(dir / "notes.partial-draft"));
  EXPECT_TRUE(fs::exists(dir / "a.partial-999999999-0x"));
}

TEST(HardeningPaths, AnImportCleansUpAfterAKilledOneAndNeverWritesOverItsRecording) {
  iotest::ScratchDir dir;
  std::vector<test_ros::OutMessage> msgs;
  for (int k = 0; k < 20; ++k) {
    test_ros::OutMessage o;
    o.topic = "/imu";
    const std::int64_t ns = 100000000000 + 5000000LL * k;
    o.imu.stamp = ros::Stamp{ns / 1000000000, static_cast<std::uint32_t>(ns % 1000000000)};
    o.receive_ns = ns + 1000;
    o.imu.frame_id = "imu";
    o.imu.accel = {0.0, 0.0, -9.8};
    msgs.push_back(o);
  }
  test_ros::write_ros2_mcap(dir / "rec.mcap", msgs);
  const fs::path out = dir / "ds";
  iotest::write_text(out / "imu_imu.bin.partial-999999999-0", "cut short");
  std::vector<std::string> warnings;
  ros::ImportOptions o;
  o.warn = [&](const std::string& m) { warnings.push_back(m); };
  EXPECT_NO_THROW(ros::import_recording(dir / "rec.mcap", out, o));  // the directory held only our temporary
  EXPECT_FALSE(fs::exists(out / "imu_imu.bin.partial-999999999-0"));
  bool said = false;
  for (const auto& w : warnings) said = said || w.find("the temporary file of an import that was killed") != std::string::npos;
  EXPECT_TRUE(said);
  // The recording inside --out under a name the import writes: refused, --force or not.
  fs::copy_file(dir / "rec.mcap", out / "manifest.yaml", fs::copy_options::overwrite_existing);
  o.force = true;
  EXPECT_HAS(error_of([&] { ros::import_recording(out / "manifest.yaml", out, o); }),
             "an output never replaces an input");
}

// simulate --force over a dataset that holds a run's results and the user's notes (issue 33,
// item 4): the dataset's own files are replaced, the rest is kept and named.
TEST(HardeningPaths, SimulateForceKeepsARunsResultsInsideTheDataset) {
  iotest::ScratchDir dir;
  ASSERT_EQ(cli("simulate --out ds --duration 30 --static 5 --chips 1 --no-ideal -q", dir.path()).code, 0);
  ASSERT_EQ(cli("run -m ds/manifest.yaml -c single -o ds/results -q", dir.path()).code, 0);
  iotest::write_text(dir / "ds" / "notes.txt", "mine\n");
  const std::string traj = iotest::read_text_file(dir / "ds" / "results" / "trajectory.csv");
  const fs::path imu = dir / "ds" / "left-wheel-imu" / "tri_C1_imu.bin";
  const auto size5 = fs::file_size(imu);
  const Cmd again = cli("simulate --out ds --duration 31 --static 5 --chips 1 --no-ideal --force", dir.path());
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_HAS(again.err, "kept what wheelins did not write there: ");
  EXPECT_HAS(again.err, "'results'");
  EXPECT_HAS(again.err, "'notes.txt'");
  EXPECT_EQ(iotest::read_text_file(dir / "ds" / "notes.txt"), "mine\n");
  EXPECT_EQ(iotest::read_text_file(dir / "ds" / "results" / "trajectory.csv"), traj);
  EXPECT_GT(fs::file_size(imu), size5);  // the 31 s dataset replaced the 30 s one
}

TEST(HardeningPaths, AStudyReportReplacesOnlyTheFilesAReportWrote) {
  iotest::ScratchDir dir;
  iotest::write_text(dir / "report.md", "# my own notes\n");
  study::ReportFiles none(dir.path());
  EXPECT_HAS(error_of([&] { none.check("report.md", "# Study: x"); }), "not written by a study report");
  iotest::write_text(dir / "summary.csv", "configuration,drift\n");  // as a report before the list wrote it
  EXPECT_NO_THROW(none.check("summary.csv", "configuration,drift"));
  study::ReportFiles ours(dir.path());
  ours.add({"summary.csv", fs::path("plots") / "a.gp"});
  iotest::write_text(dir / "plots" / "a.gp", "anything\n");
  study::ReportFiles again(dir.path());
  EXPECT_NO_THROW(again.check(fs::path("plots") / "a.gp", ""));
  EXPECT_HAS(error_of([&] { again.check("report.md", "# my own notes"); }), "not written by a study report");
}

// ------------------------------------------------------------------ the command line

TEST(HardeningPaths, CommandLineOutputsAreCheckedBeforeAnythingIsWritten) {
  iotest::ScratchDir dir;
  // An empty value is an error naming the option, never "not given".
  Cmd c = cli("run -m m.yaml -o ''", dir.path());
  EXPECT_EQ(c.code, 2);
  EXPECT_HAS(c.err, "--out: an empty value");
  c = cli("study run s.yaml --job ''", dir.path());
  EXPECT_EQ(c.code, 2);
  EXPECT_HAS(c.err, "--job: an empty value");
  // evaluate: the same file for --json and --series is refused before either is written;
  // an output that is an input is refused with --force.
  iotest::write_text(dir / "truth.txt", "not read\n");
  iotest::write_text(dir / "traj.csv", "not read\n");
  c = cli("evaluate --truth truth.txt --traj traj.csv --json F --series F", dir.path());
  EXPECT_EQ(c.code, 2);
  EXPECT_HAS(c.err, "the same file as --json");
  EXPECT_FALSE(fs::exists(dir / "F"));
  c = cli("evaluate --truth truth.txt --traj traj.csv --series traj.csv --force", dir.path());
  EXPECT_EQ(c.code, 2);
  EXPECT_HAS(c.err, "--series 'traj.csv': is");
  EXPECT_EQ(iotest::read_text_file(dir / "traj.csv"), "not read\n");
  // calibrate: --report set to the input manifest names --report.
  iotest::write_text(dir / "m.yaml", manifest_with(wheel("left", "left.bin")));
  c = cli("calibrate -m m.yaml -o refined.yaml --report m.yaml --force", dir.path());
  EXPECT_EQ(c.code, 2);
  EXPECT_HAS(c.err, "--report 'm.yaml'");
  EXPECT_EQ(c.err.find("--out 'refined.yaml'"), std::string::npos) << c.err;
}
