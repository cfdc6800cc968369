// One run session for every feeder (issue 35): records pushed one at a time (PushSession, as
// the Python Navigator and a live source push them) give the files a run of the manifest's
// files gives, to the byte; pushed records are checked as the file reader checks them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include "dataset_test_util.hpp"
#include "io_test_util.hpp"
#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/run/evaluation.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/push_session.hpp"
#include "wheelins/run/run.hpp"

using namespace wheelins;
namespace fs = std::filesystem;

namespace {

class RunSessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new iotest::ScratchDir();
    dstest::simulate_short(dir_->path() / "data", 70.0);  // 30 s of it standing
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static RunRequest request(const std::string& configuration, const fs::path& out) {
    RunRequest r;
    r.manifest = load_manifest(dir_->path() / "data" / "manifest.yaml", {});
    r.modules = configuration_modules(r.manifest, configuration, {});
    r.output_dir = out;
    r.formats = {TrajectoryFormat::kCsv, TrajectoryFormat::kTum};
    r.file_interval = 0.1;
    r.progress = false;
    r.calibration = CalibrationMode::kManifest;  // a warm-up's estimates differ from a file pass's
    return r;
  }
  /// The request's modules' records as their files hold them, in time order (ties in module
  /// order, as the file run merges them: the simulated manifest has no time offsets).
  static std::vector<std::pair<int, ImuRow>> merged_rows(const RunRequest& r) {
    std::vector<std::tuple<double, int, std::size_t>> order;
    std::vector<std::vector<double>> data;
    for (std::size_t i = 0; i < r.modules.size(); ++i) {
      data.push_back(dstest::read_doubles(r.manifest.resolve(r.manifest.find(r.modules[i])->file)));
      for (std::size_t k = 0; k + 7 <= data.back().size(); k += 7) order.emplace_back(data.back()[k], int(i), k);
    }
    std::sort(order.begin(), order.end());
    std::vector<std::pair<int, ImuRow>> rows;
    for (const auto& [t, i, k] : order) {
      const double* v = &data[static_cast<std::size_t>(i)][k];
      ImuRow row;
      row.t = v[0];
      row.gyro = Vec3(v[1], v[2], v[3]);
      row.accel = Vec3(v[4], v[5], v[6]);
      rows.emplace_back(i, row);
    }
    return rows;
  }
  static iotest::ScratchDir* dir_;
};
iotest::ScratchDir* RunSessionTest::dir_ = nullptr;

TEST_F(RunSessionTest, PushedRecordsWriteTheFilesOfARunOfTheFiles) {
  for (const char* configuration : {"single", "triple"}) {
    SCOPED_TRACE(configuration);
    const fs::path a = dir_->path() / (std::string("files-") + configuration);
    const fs::path b = dir_->path() / (std::string("pushed-") + configuration);
    RunRequest f = request(configuration, a);
    std::size_t file_records = 0;
    f.on_record = [&](const TrajectoryRecord&) { ++file_records; };
    const RunResult from_files = run_navigation(f);

    RunRequest r = request(configuration, b);
    std::size_t records = 0;
    r.on_record = [&](const TrajectoryRecord&) { ++records; };
    PushSession session(r, 60.0);
    for (const auto& [i, row] : merged_rows(r)) ASSERT_TRUE(session.push(i, row));
    const RunResult pushed = session.finish();

    EXPECT_GT(records, 1000u);
    EXPECT_EQ(records, file_records);
    ASSERT_EQ(pushed.files.size(), from_files.files.size());
    ASSERT_GE(pushed.files.size(), 4u);  // trajectory.csv, .tum, faults.csv, noise.yaml (+ per module)
    for (std::size_t k = 0; k < pushed.files.size(); ++k) {
      SCOPED_TRACE(pushed.files[k].string());
      EXPECT_EQ(pushed.files[k].filename(), from_files.files[k].filename());
      EXPECT_EQ(iotest::read_text_file(pushed.files[k]), iotest::read_text_file(from_files.files[k]));
    }
    EXPECT_EQ(pushed.stats.epochs, from_files.stats.epochs);
    EXPECT_EQ(pushed.fault_report, from_files.fault_report);
    EXPECT_THROW(session.push(0, ImuRow{}), InputError);  // after finish()
  }
}

TEST_F(RunSessionTest, PushedRecordsAreCheckedAsTheFileReaderChecksThem) {
  RunRequest r = request("single", {});
  const std::vector<std::pair<int, ImuRow>> rows = merged_rows(r);
  {
    PushSession s(r, 60.0);
    ASSERT_TRUE(s.push(0, rows[0].second));
    EXPECT_HAS(iotest::error_of([&] { s.push(0, rows[0].second); }), "sample 1 (0-based): time");
    EXPECT_HAS(iotest::error_of([&] { s.push(0, rows[0].second); }), "repeats the previous sample's time");
    ImuRow bad = rows[1].second;
    bad.accel.y() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_HAS(iotest::error_of([&] { s.push(0, bad); }), "column 5 (accel_y): value is NaN");
    EXPECT_HAS(iotest::error_of([&] { s.push(3, rows[1].second); }), "module index 3 out of range");
  }
  {
    // The data end inside the static period: nothing to navigate, and the error says whose.
    PushSession s(r, 60.0, "the live source");
    for (std::size_t k = 0; k < 100; ++k) ASSERT_TRUE(s.push(0, rows[k].second));
    EXPECT_HAS(iotest::error_of([&] { s.finish(); }), "'the live source of " + r.modules[0] + "': the data end");
  }
  r.calibration = CalibrationMode::kEstimate;
  EXPECT_HAS(iotest::error_of([&] { PushSession(r, 0.0); }), "calibration_warmup must be a positive");
}

TEST_F(RunSessionTest, AWarmUpEstimatesTheInstallationAndTheRunWritesIt) {
  // A warm-up that ends inside the data (then the kept samples are navigated), and one longer
  // than the data (it ends with them, at finish()).
  for (const double warmup : {5.0, 1000.0}) {
    SCOPED_TRACE(warmup);
    const fs::path out = dir_->path() / ("warmup-" + std::to_string(int(warmup)));
    RunRequest r = request("body-wheel", out);
    r.calibration = CalibrationMode::kEstimate;
    PushSession s(r, warmup);
    bool navigated_during_warmup = false;
    for (const auto& [i, row] : merged_rows(r)) {
      ASSERT_TRUE(s.push(i, row));
      if (s.in_warmup() && s.navigator().navigating()) navigated_during_warmup = true;
    }
    EXPECT_FALSE(navigated_during_warmup);
    EXPECT_EQ(s.calibrated(), warmup < 10.0);
    const RunResult res = s.finish();
    EXPECT_TRUE(s.calibrated());
    EXPECT_GT(res.stats.epochs, 1000u);
    ASSERT_FALSE(res.calibration.empty());
    const std::string yaml = iotest::read_text_file(out / "calibration.yaml");
    for (const auto& m : r.modules) EXPECT_HAS(yaml, m);
  }
}

TEST_F(RunSessionTest, TheRunsEvaluationIsTheOneEveryFrontEndGets) {
  // The session evaluates the vehicle solution with the manifest's settings: the same figures
  // as an evaluation made by hand from the records with run_evaluation_options().
  RunRequest r = request("body-wheel", "");
  r.evaluation = RunEvaluationRequest{};
  const eval::RunEvaluationOptions eo = run_evaluation_options(r.manifest, *r.evaluation);
  ASSERT_TRUE(r.manifest.truth_file.has_value());
  eval::RunEvaluation by_hand(r.manifest.resolve(*r.manifest.truth_file), r.manifest.origin, eo);
  r.on_record = [&](const TrajectoryRecord& rec) { by_hand.add(rec); };
  const RunResult res = run_navigation(r);
  ASSERT_TRUE(res.evaluation.has_value()) << res.evaluation_error;
  const eval::EvalResult e = by_hand.finish();
  EXPECT_GT(res.evaluation->distance, 10.0);  // (too short a run for a drift rate: no segment)
  EXPECT_EQ(res.evaluation->epochs, e.epochs);
  EXPECT_EQ(res.evaluation->heading_rmse, e.heading_rmse);
  EXPECT_EQ(res.evaluation->final_error, e.final_error);
  EXPECT_EQ(res.truth_file, r.manifest.resolve(*r.manifest.truth_file));

  // The settings: a local frame (no initial heading) is aligned over 100 m unless told.
  Manifest m = r.manifest;
  m.heading_known = true;
  EXPECT_EQ(run_evaluation_options(m, {}).eval.align_start, 0.0);
  m.heading_known = false;
  EXPECT_EQ(run_evaluation_options(m, {}).eval.align_start, kDefaultAlignStart);
  EXPECT_EQ(run_evaluation_options(m, RunEvaluationRequest{5.0, "", false, ""}).eval.align_start, 5.0);
  EXPECT_EQ(run_evaluation_options(m, RunEvaluationRequest{{}, "0.5,0,-1.2", false, ""}).eval.antenna,
            Vec3(0.5, 0.0, -1.2));
  EXPECT_HAS(iotest::error_of([&] { run_evaluation_options(m, RunEvaluationRequest{{}, "1,2", false, ""}); }),
             "--antenna '1,2': expected X,Y,Z");

  // A truth file that cannot be read stops the run before any work: no output directory.
  const fs::path out = dir_->path() / "no-truth";
  RunRequest bad = request("body-wheel", out);
  bad.evaluation = RunEvaluationRequest{};
  bad.manifest.truth_file = "missing-truth.txt";
  EXPECT_HAS(iotest::error_of([&] { run_navigation(bad); }), "missing-truth.txt");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace

TEST_F(RunSessionTest, AWarmUpsKeptSamplesNavigatedASliceAtATimeGiveTheSameRun) {
  // All at once (0), a slice of 200 per push (caught up inside the data) and 1 per push (never
  // caught up: finish() navigates the rest): the same files to the byte.
  std::vector<std::string> trajectories;
  for (const std::size_t slice : {std::size_t{0}, std::size_t{200}, std::size_t{1}}) {
    SCOPED_TRACE(slice);
    const fs::path out = dir_->path() / ("catch-up-" + std::to_string(slice));
    RunRequest r = request("body-wheel", out);
    r.calibration = CalibrationMode::kEstimate;
    PushSession s(r, 5.0);
    s.set_catch_up(slice);
    std::size_t pushes_behind = 0;
    for (const auto& [i, row] : merged_rows(r)) {
      ASSERT_TRUE(s.push(i, row));
      if (s.behind()) ++pushes_behind;
      EXPECT_FALSE(s.behind() && s.in_warmup());
    }
    if (slice == 0) {
      EXPECT_EQ(pushes_behind, 0u);
    } else if (slice == 200) {
      EXPECT_GT(pushes_behind, 10u);
      EXPECT_FALSE(s.behind());
    } else {
      EXPECT_TRUE(s.behind());
    }
    s.finish();
    EXPECT_FALSE(s.behind());
    trajectories.push_back(iotest::read_text_file(out / "trajectory.csv"));
    EXPECT_GT(trajectories.back().size(), 10000u);
  }
  EXPECT_EQ(trajectories[1], trajectories[0]);
  EXPECT_EQ(trajectories[2], trajectories[0]);
}
