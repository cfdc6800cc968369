// What `wheelins run` prints and writes by default (issue 35: quiet and sized by default), and
// what -v, --full-rate and --subsystems add.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "dataset_test_util.hpp"
#include "io_test_util.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/run/run_config.hpp"

using namespace wheelins;
using namespace wheelins::dstest;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// The line of `text` that starts with `prefix` (after blanks), or "".
std::string line_of(const std::string& text, const std::string& prefix) {
  for (const auto& l : lines(text))
    if (l.find_first_not_of(' ') != std::string::npos && l.substr(l.find_first_not_of(' ')).rfind(prefix, 0) == 0)
      return l;
  return "";
}

class RunOutput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new iotest::ScratchDir();
    const CmdResult sim =
        wheelins_cli("simulate --out " + q(dir_->path() / "ds") + " --duration 70 --static 10 --chips 1 --no-ideal -q", dir_->path());
    ASSERT_EQ(sim.code, 0) << sim.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static CmdResult run(const std::string& out, const std::string& flags) {
    return wheelins_cli("run -q -m " + q(dir_->path() / "ds" / "manifest.yaml") + " -c triple -o " +
                            q(dir_->path() / out) + " " + flags,
                        dir_->path());
  }
  static iotest::ScratchDir* dir_;
};
iotest::ScratchDir* RunOutput::dir_ = nullptr;

TEST_F(RunOutput, ASummaryByDefaultTheTablesWithVerbose) {
  const CmdResult r = run("short", "");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_LE(lines(r.out).size(), 20u) << r.out;
  EXPECT_EQ(r.out.find("filter.velocity_update_hz"), std::string::npos) << r.out;  // the option listing
  EXPECT_NE(line_of(r.out, "wrote 7 files to ").find("--full-rate"), std::string::npos) << r.out;
  EXPECT_NE(line_of(r.out, "reference weights k_i (eq. 8), mean: left-C1 0.333"), "") << r.out;
  EXPECT_NE(line_of(r.out, "drift rate"), "") << r.out;
  // Warnings: whole lines on stderr, each once.
  std::set<std::string> seen;
  for (const auto& l : lines(r.err)) {
    EXPECT_EQ(l.rfind("warning: ", 0), 0u) << l;
    EXPECT_TRUE(seen.insert(l).second) << "said twice: " << l;
  }

  const CmdResult v = run("verbose", "-v");
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.out.find("  filter.velocity_update_hz"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("installation calibration (estimate"), std::string::npos) << v.out;
  EXPECT_NE(v.out.find("wrote " + (dir_->path() / "verbose" / "trajectory.csv").string()), std::string::npos);
  EXPECT_GT(lines(v.out).size(), lines(r.out).size() + 15);
  // The same run: the same figures.
  EXPECT_EQ(line_of(v.out, "drift rate"), line_of(r.out, "drift rate"));
}

TEST_F(RunOutput, TrajectoryEveryTenthOfASecondUnlessFullRate) {
  const CmdResult r = run("sized", "--formats csv,tum");
  ASSERT_EQ(r.code, 0) << r.err;
  const CmdResult f = run("full", "--formats csv,tum --full-rate --subsystems");
  ASSERT_EQ(f.code, 0) << f.err;
  const auto sized = read_trajectory(dir_->path() / "sized" / "trajectory.csv").records;
  const auto full = read_trajectory(dir_->path() / "full" / "trajectory.csv").records;
  ASSERT_GT(sized.size(), 500u);  // 60 s at 10 Hz
  // Every record at full rate (200 Hz); at 10 Hz by default, the first and the last kept.
  EXPECT_GT(full.size(), 19 * sized.size());
  EXPECT_EQ(sized.front().t, full.front().t);
  EXPECT_EQ(sized.back().t, full.back().t);
  for (std::size_t k = 1; k + 1 < sized.size(); ++k)
    ASSERT_NEAR(sized[k].t - sized[k - 1].t, 0.1, 0.0051) << k;
  // The kept records are the full-rate ones, to the digit.
  std::size_t j = 0;
  for (const TrajectoryRecord& s : sized) {
    while (j < full.size() && full[j].t < s.t) ++j;
    ASSERT_LT(j, full.size());
    ASSERT_EQ(full[j].t, s.t);
    ASSERT_EQ(full[j].p_inN, s.p_inN);
  }
  // The evaluation sees every record either way.
  EXPECT_EQ(line_of(r.out, "drift rate"), line_of(f.out, "drift rate"));
  EXPECT_EQ(line_of(r.out, "max / final error"), line_of(f.out, "max / final error"));
  // Each IMU's own trajectory only on request.
  EXPECT_FALSE(fs::exists(dir_->path() / "sized" / "left-C1.csv"));
  EXPECT_TRUE(fs::exists(dir_->path() / "full" / "left-C1.csv"));
  EXPECT_LT(fs::file_size(dir_->path() / "sized" / "trajectory.csv") * 15,
            fs::file_size(dir_->path() / "full" / "trajectory.csv"));
}

TEST_F(RunOutput, TheFileIntervalIsCheckedWhereItIsRead) {
  iotest::write_text(dir_->path() / "bad.yaml", "dataset: ds/manifest.yaml\noutput:\n  file_interval_s: -1\n");
  const CmdResult r =
      wheelins_cli("run -q " + q(dir_->path() / "bad.yaml") + " -o " + q(dir_->path() / "never"), dir_->path());
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("output.file_interval_s"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_->path() / "never"));
}

TEST(WarningSinkTest, StderrSinkSaysEachWarningOnceAsAWholeLine) {
  const WarningSink warn = stderr_sink();
  testing::internal::CaptureStderr();
  warn("left-C1: something");
  warn("right-C1: something else");
  warn("left-C1: something");
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "warning: left-C1: something\nwarning: right-C1: something else\n");
}

}  // namespace

namespace {

// One function applies the command line's flags and Python's keywords over a run configuration.
TEST_F(RunOutput, OverridesApplyOverTheConfigurationFile) {
  iotest::write_text(dir_->path() / "cfg.yaml",
                     "dataset: ds/manifest.yaml\nconfiguration: dual-wheel\nmodules: [left-C1]\n"
                     "output:\n  file_interval_s: 0.5\n  subsystems: false\n"
                     "fusion:\n  weights: [0.5, 0.5]\n");
  RunOverrides o;
  o.config = dir_->path() / "cfg.yaml";
  RunConfig c = run_config_with(o, {});
  EXPECT_EQ(c.modules, std::vector<std::string>{"left-C1"});
  EXPECT_DOUBLE_EQ(c.file_interval, 0.5);
  EXPECT_EQ(c.nav.fusion.weights.size(), 2u);

  o.named = {cli_setting("-c", "triple"),  // over the file's configuration and its module list
             cli_setting("--weights", "covariance"),  // over the file's fixed weights
             cli_setting("--full-rate"), cli_setting("--subsystems"), cli_setting("--fixed-noise")};
  c = run_config_with(o, {});
  EXPECT_EQ(c.configuration, "triple");
  EXPECT_TRUE(c.modules.empty());
  EXPECT_TRUE(c.nav.fusion.weights.empty());
  EXPECT_EQ(c.nav.fusion.weighting, ReferenceWeighting::kCovariance);
  EXPECT_DOUBLE_EQ(c.file_interval, 0.0);
  EXPECT_TRUE(c.write_subsystems);
  EXPECT_FALSE(c.nav.noise.enabled);

  o.named.push_back(cli_setting("--modules", "left-C1"));  // both ways of choosing the IMUs: an error
  EXPECT_THROW(run_config_with(o, {}), InputError);
  RunOverrides none;
  EXPECT_THROW(run_config_with(none, {}), InputError);  // no dataset
}

}  // namespace
