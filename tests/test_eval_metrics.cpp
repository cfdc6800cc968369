// The evaluation metrics on synthetic trajectories with hand-computed answers.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "wheelins/eval/metrics.hpp"
#include "wheelins/nav/types.hpp"

using namespace wheelins;
using namespace wheelins::eval;

namespace {

const earth::Geodetic kOrigin{30.5 * kDeg, 114.3 * kDeg, 20.0};

// Truth records from a function t -> (ned, heading).
TruthData make_truth(const earth::LocalFrame& frame, double t0, double t1, double dt,
                     const std::function<Vec3(double)>& pos,
                     const std::function<double(double)>& heading) {
  TruthData d;
  d.file = "truth.bin";
  const int n = static_cast<int>(std::llround((t1 - t0) / dt));
  for (int i = 0; i <= n; ++i) {
    const double t = t0 + i * dt;
    TruthRecord r;
    r.t = t;
    r.lla = frame.geodetic_from_ned(pos(t));
    r.rpy = Vec3(0, 0, heading(t));
    d.records.push_back(r);
  }
  return d;
}

TrajectoryData make_traj(double t0, double t1, double dt, const std::function<Vec3(double)>& pos,
                         const std::function<double(double)>& heading) {
  TrajectoryData d;
  d.file = "traj.csv";
  d.has_ned = true;
  d.has_heading = true;
  const int n = static_cast<int>(std::llround((t1 - t0) / dt));
  for (int i = 0; i <= n; ++i) {
    const double t = t0 + i * dt;
    TrajectoryRecord r;
    r.t = t;
    r.p_inN = pos(t);
    r.rpy = Vec3(0, 0, heading(t));
    d.records.push_back(r);
  }
  return d;
}

}  // namespace

TEST(EvalMetrics, DriftRateCurveByHand) {
  // Errors 1 m at 50 m, 4 m at 120 m, 2 m at 250 m, 0.5 m at 310 m; l = 100 m, K = 3.
  const std::vector<double> s = {0, 50, 120, 250, 310};
  const std::vector<double> e = {0, 1, 4, 2, 0.5};
  const auto c = drift_rate_curve(s, e, 100.0);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_DOUBLE_EQ(c[0], 1.0 / 100.0);  // max over s <= 100 is 1
  EXPECT_DOUBLE_EQ(c[1], 4.0 / 200.0);  // max over s <= 200 is 4
  EXPECT_DOUBLE_EQ(c[2], 4.0 / 300.0);  // still 4 (loop closure does not lower the max)
  EXPECT_TRUE(drift_rate_curve({0, 99.9}, {0, 1}, 100.0).empty());
}

TEST(EvalMetrics, DriftRateStraightLineKnownGrowth) {
  // Truth: due north at 1 m/s for 350 s (350 m), 1 Hz. The trajectory's east error
  // grows 2 cm per metre up to 3 m at s = 150 m and then shrinks linearly to 1 m at
  // s = 350 m:
  //   k = 1: max error over s <= 100 m is 2 m  -> 2 / 100 = 2.0 %
  //   k = 2: max over s <= 200 m is 3 m (s=150) -> 3 / 200 = 1.5 %
  //   k = 3: max over s <= 300 m is 3 m        -> 3 / 300 = 1.0 %
  //   K = floor(350 / 100) = 3, drift rate = (2 + 1.5 + 1) / 3 = 1.5 %.
  const earth::LocalFrame frame(kOrigin);
  auto err = [](double s) { return s <= 150.0 ? 0.02 * s : 3.0 - (s - 150.0) * 0.01; };
  const auto truth = make_truth(
      frame, 0, 350, 1.0, [](double t) { return Vec3(t, 0, 0); }, [](double) { return 0.0; });
  const auto traj = make_traj(
      0, 350, 0.1, [&](double t) { return Vec3(t, err(t), 0); }, [](double) { return 0.0; });
  const EvalResult r = evaluate(truth, traj, frame);
  EXPECT_EQ(r.epochs, 351u);
  EXPECT_NEAR(r.distance, 350.0, 1e-6);
  EXPECT_NEAR(r.duration, 350.0, 1e-12);
  ASSERT_EQ(r.drift_curve.size(), 3u);
  EXPECT_NEAR(r.drift_curve[0], 0.020, 1e-9);
  EXPECT_NEAR(r.drift_curve[1], 0.015, 1e-9);
  EXPECT_NEAR(r.drift_curve[2], 0.010, 1e-9);
  EXPECT_NEAR(r.drift_rate, 0.015, 1e-9);
  EXPECT_NEAR(r.max_error, 3.0, 1e-6);
  EXPECT_NEAR(r.final_error, 1.0, 1e-6);
  EXPECT_NEAR(r.heading_rmse, 0.0, 1e-12);

  // l = 200 m: K = 1, r_1 = 3 / 200.
  EvalOptions o;
  o.segment_length = 200.0;
  EXPECT_NEAR(evaluate(truth, traj, frame, o).drift_rate, 0.015, 1e-9);
  // l = 400 m > distance: undefined.
  o.segment_length = 400.0;
  EXPECT_TRUE(std::isnan(evaluate(truth, traj, frame, o).drift_rate));
}

TEST(EvalMetrics, HeadingWrapAndShortestArc) {
  const earth::LocalFrame frame(kOrigin);
  // Truth 359 deg, trajectory 1 deg: a 2 deg error, not 358.
  const auto truth = make_truth(
      frame, 0, 10, 1.0, [](double t) { return Vec3(t, 0, 0); },
      [](double) { return 359.0 * kDeg; });
  const auto traj = make_traj(
      0, 10, 1.0, [](double t) { return Vec3(t, 0, 0); }, [](double) { return 1.0 * kDeg; });
  const EvalResult r = evaluate(truth, traj, frame);
  EXPECT_TRUE(r.has_heading);
  EXPECT_NEAR(r.heading_rmse / kDeg, 2.0, 1e-9);
  EXPECT_NEAR(r.series[3].heading_err / kDeg, 2.0, 1e-9);  // sign: traj - truth

  // Interpolation across the +-180 seam: trajectory 179 deg at t=0, -179 deg at t=1.
  // At t=0.5 the shorter arc gives 180 deg (the long way would give 0 deg).
  TruthData t2 = make_truth(
      frame, 0.5, 0.5, 1.0, [](double) { return Vec3(0, 0, 0); }, [](double) { return kPi; });
  TrajectoryData j2 = make_traj(
      0, 1, 1.0, [](double) { return Vec3(0, 0, 0); },
      [](double t) { return t < 0.5 ? 179.0 * kDeg : -179.0 * kDeg; });
  const EvalResult r2 = evaluate(t2, j2, frame);
  ASSERT_EQ(r2.epochs, 1u);
  EXPECT_NEAR(r2.heading_rmse, 0.0, 1e-12);
}

TEST(EvalMetrics, InterpolatesTrajectoryToTruthTimes) {
  const earth::LocalFrame frame(kOrigin);
  // Trajectory corners (0,0) t=0, (10,0) t=1, (10,10) t=2; truth at t = 0.25 sits 1 m east
  // of the trajectory's (2.5, 0), at t = 1.5 exactly on (10, 5).
  TrajectoryData traj;
  traj.file = "traj.tum";
  traj.has_ned = true;
  const Vec3 corners[3] = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}};
  for (int i = 0; i < 3; ++i) {
    TrajectoryRecord r;
    r.t = i;
    r.p_inN = corners[i];
    traj.records.push_back(r);
  }
  TruthData truth;
  truth.file = "truth.bin";
  truth.has_velocity = truth.has_attitude = false;
  truth.layout = TruthLayout::kPos5;
  const double ts[4] = {-1.0, 0.25, 1.5, 3.0};  // the first and last lie outside
  const Vec3 ps[4] = {{0, 0, 0}, {2.5, 1, 0}, {10, 5, 0}, {10, 10, 0}};
  for (int i = 0; i < 4; ++i) {
    TruthRecord r;
    r.t = ts[i];
    r.lla = frame.geodetic_from_ned(ps[i]);
    truth.records.push_back(r);
  }
  const EvalResult r = evaluate(truth, traj, frame);
  ASSERT_EQ(r.epochs, 2u);
  EXPECT_EQ(r.skipped_outside, 2u);
  EXPECT_NEAR(r.series[0].err_ned.y(), -1.0, 1e-7);
  EXPECT_NEAR(r.series[0].err_h, 1.0, 1e-7);
  EXPECT_NEAR(r.series[1].err_h, 0.0, 1e-7);
  EXPECT_NEAR(r.max_error, 1.0, 1e-7);
  EXPECT_NEAR(r.final_error, 0.0, 1e-7);
  // Distance along the truth from (2.5,1) to (10,5).
  EXPECT_NEAR(r.distance, std::hypot(7.5, 4.0), 1e-6);
  // No truth attitude (5-column truth): heading metrics are skipped.
  EXPECT_FALSE(r.has_heading);
  EXPECT_TRUE(std::isnan(r.heading_rmse));
  EXPECT_FALSE(r.has_sigma);

  // Both inner truth epochs sit in 1 s trajectory intervals: with max_gap 0.9 s nothing
  // is left to evaluate, and the error says why.
  EvalOptions o;
  o.max_gap = 0.9;
  try {
    evaluate(truth, traj, frame, o);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gaps"), std::string::npos) << e.what();
  }
}

TEST(EvalMetrics, SkipsTruthEpochsInTrajectoryGaps) {
  const earth::LocalFrame frame(kOrigin);
  const auto truth = make_truth(
      frame, 0, 6, 1.0, [](double t) { return Vec3(t, 0, 0); }, [](double) { return 0.0; });
  TrajectoryData traj;
  traj.file = "gappy.csv";
  traj.has_ned = true;
  for (double t : {0.0, 0.5, 1.0, 1.5, 4.5, 5.0, 6.0}) {  // 3 s gap between 1.5 and 4.5
    TrajectoryRecord r;
    r.t = t;
    r.p_inN = Vec3(t, 0, 0);
    traj.records.push_back(r);
  }
  EvalOptions o;
  o.max_gap = 2.0;
  const EvalResult r = evaluate(truth, traj, frame, o);
  EXPECT_EQ(r.skipped_gap, 3u);  // t = 2, 3, 4
  EXPECT_EQ(r.epochs, 4u);       // t = 0, 1, 5, 6
  EXPECT_EQ(r.series[2].t, 5.0);
  // Distance still follows the truth through the gap.
  EXPECT_NEAR(r.series[2].distance, 5.0, 1e-6);
  // Across the gap the records are 3 s apart, sparser than the 1 s truth: with a larger
  // max_gap the epochs in it are not interpolated either (skipped_sparse); the scored epochs
  // either side, 4 s apart, are within max_gap: the truth's 6 s count as covered, and
  // with max_gap 2 s only 2 of them.
  o.max_gap = 5.0;
  const EvalResult r5 = evaluate(truth, traj, frame, o);
  EXPECT_EQ(r5.epochs, 4u);
  EXPECT_EQ(r5.skipped_sparse, 3u);
  EXPECT_NEAR(r5.covered, 6.0, 1e-9);
  EXPECT_TRUE(r5.comparable);
  EXPECT_NEAR(r.covered, 2.0, 1e-9);
  EXPECT_FALSE(r.comparable);
}

// Issue 33, 7: a trajectory missing most of its records, or of two records, scored a small
// drift rate with no word. Coverage (the time between scored epochs over the truth's span)
// marks such results not comparable, in the result, its JSON and a warning.
TEST(EvalMetrics, CoverageMarksPartialTrajectoriesNotComparable) {
  const earth::LocalFrame frame(kOrigin);
  auto pos = [](double t) { return Vec3(10.0 * t, 0.01 * t * t, 0); };  // error grows with t
  auto truth_pos = [](double t) { return Vec3(10.0 * t, 0, 0); };
  auto zero = [](double) { return 0.0; };
  const auto truth = make_truth(frame, 0, 600, 1.0, truth_pos, zero);
  const EvalResult full = evaluate(truth, make_traj(0, 600, 0.1, pos, zero), frame);
  EXPECT_TRUE(full.comparable);
  EXPECT_NEAR(full.coverage, 1.0, 1e-9);
  EXPECT_TRUE(coverage_warning(full).empty());
  EXPECT_NE(to_json(full).find("\"comparable\": true"), std::string::npos);

  // 87 % of the records gone: the first 13 % kept.
  const EvalResult part = evaluate(truth, make_traj(0, 78, 0.1, pos, zero), frame);
  EXPECT_LT(part.drift_rate, full.drift_rate);  // what made the figure misleading
  EXPECT_FALSE(part.comparable);
  EXPECT_NEAR(part.coverage, 78.0 / 600.0, 1e-9);
  EXPECT_NE(coverage_warning(part).find("NOT comparable"), std::string::npos) << coverage_warning(part);
  EXPECT_NE(to_json(part).find("\"comparable\": false"), std::string::npos);
  // Every eighth second kept (gaps of 7 s > max_gap 5 s).
  TrajectoryData holes = make_traj(0, 600, 0.1, pos, zero);
  std::vector<TrajectoryRecord> kept;
  for (const auto& r : holes.records)
    if (std::fmod(r.t + 1e-9, 8.0) < 1.0) kept.push_back(r);
  holes.records = kept;
  const EvalResult h = evaluate(truth, holes, frame);
  EXPECT_FALSE(h.comparable);
  EXPECT_GT(h.skipped_gap, 400u);
  // Two records, at the start and the end.
  TrajectoryData two = make_traj(0, 600, 600, pos, zero);
  ASSERT_EQ(two.records.size(), 2u);
  const EvalResult t2 = evaluate(truth, two, frame);
  EXPECT_FALSE(t2.comparable);
  EXPECT_EQ(t2.coverage, 0.0);
}

// Issue 33, 8: records 5 s apart (run --output-interval 5) against a 10 Hz truth were
// interpolated along straight lines, which in a turn is neither the path nor the heading the
// filter computed. They are scored where they fall on truth epochs, exactly.
TEST(EvalMetrics, SparseRecordsAreScoredAtTheirOwnEpochs) {
  const earth::LocalFrame frame(kOrigin);
  // A circle of 50 m radius at 10 m/s, the yaw rate changing (a slalom on top).
  auto heading = [](double t) { return 0.2 * t + 0.3 * std::sin(0.5 * t); };
  // The path on the 0.1 s grid, integrated at 10 m/s in 10 ms steps along the heading.
  std::vector<Vec3> path(1, Vec3::Zero());
  Vec3 p = Vec3::Zero();
  for (int i = 0; i < 6000; ++i) {
    const double h = heading((i + 0.5) * 0.01);
    p += 0.1 * Vec3(std::cos(h), std::sin(h), 0.0);
    if ((i + 1) % 10 == 0) path.push_back(p);
  }
  auto grid = [&](double t) { return path[static_cast<std::size_t>(std::llround(t / 0.1))]; };
  const auto truth = make_truth(frame, 0, 60, 0.1, grid, heading);
  const EvalResult sparse = evaluate(truth, make_traj(0, 60, 5.0, grid, heading), frame);
  EXPECT_EQ(sparse.epochs, 13u);  // t = 0, 5, ..., 60
  EXPECT_EQ(sparse.skipped_sparse, 600u - 12u);
  EXPECT_LT(sparse.max_error, 1e-6);
  EXPECT_LT(sparse.heading_rmse, 1e-9);
  EXPECT_TRUE(sparse.comparable);  // its epochs span the truth, 5 s apart
  // Dense records (0.1 s) are interpolated at the truth epochs as before.
  const EvalResult dense = evaluate(truth, make_traj(0, 60, 0.1, grid, heading), frame);
  EXPECT_EQ(dense.epochs, 601u);
  EXPECT_EQ(dense.skipped_sparse, 0u);
}

// Issue 33, 10: the errors of a lat/lon trajectory were taken as "horizontal" in the frame of
// evaluate --origin, which far from the data mixes in the height error. They are taken in the
// truth point's own north/east/down, and the distance in the truth's own frame.
TEST(EvalMetrics, LatLonFiguresDoNotDependOnTheFrameOrigin) {
  const earth::LocalFrame here(kOrigin);
  auto truth_pos = [](double t) { return Vec3(10.0 * t, 2.0 * t, 0.5 * std::sin(t)); };
  auto zero = [](double) { return 0.0; };
  const auto truth = make_truth(here, 0, 300, 1.0, truth_pos, zero);
  TrajectoryData traj;
  traj.file = "traj.csv";
  traj.has_lla = true;
  traj.has_heading = true;
  for (int k = 0; k <= 3000; ++k) {
    const double t = 0.1 * k;
    TrajectoryRecord r;
    r.t = t;
    // 0.1 m north, 0.05 m east and 2 m of height error growing with time.
    r.lla = here.geodetic_from_ned(truth_pos(t) + Vec3(0.1, 0.05, -2.0 * t / 300.0));
    traj.records.push_back(r);
  }
  const EvalResult a = evaluate(truth, traj, here);
  EXPECT_NEAR(a.final_error, std::hypot(0.1, 0.05), 2e-3);  // (the offsets are in the frame at the start)
  for (const double km : {100.0, 1000.0}) {
    const earth::LocalFrame far(here.geodetic_from_ned(Vec3(0.6 * km * 1e3, 0.8 * km * 1e3, 0.0)));
    const EvalResult b = evaluate(truth, traj, far);
    EXPECT_NEAR(b.final_error, a.final_error, 1e-6) << km;
    EXPECT_NEAR(b.max_error, a.max_error, 1e-6) << km;
    EXPECT_NEAR(b.distance, a.distance, 1e-6) << km;
    EXPECT_NEAR(b.drift_rate, a.drift_rate, 1e-9) << km;
  }
}

TEST(EvalMetrics, SigmaFractionAndNees) {
  const earth::LocalFrame frame(kOrigin);
  // Four epochs, sigma_n = 1, sigma_e = 2 -> sigma_h = sqrt(5) = 2.236, 3 sigma_h = 6.708.
  // Errors (dn, de): (1, 0), (0, 2), (3, 4) and (6, 4), i.e. |e| = 1, 2, 5, 7.211 m.
  const Vec3 errs[4] = {{1, 0, 0}, {0, 2, 0}, {3, 4, 0}, {6, 4, 0}};
  TruthData truth;
  truth.file = "truth.bin";
  TrajectoryData traj;
  traj.file = "traj.csv";
  traj.has_ned = traj.has_pos_std = true;
  for (int i = 0; i < 4; ++i) {
    TruthRecord tr;
    tr.t = i;
    tr.lla = frame.geodetic_from_ned(Vec3(10.0 * i, 0, 0));
    truth.records.push_back(tr);
    TrajectoryRecord r;
    r.t = i;
    r.p_inN = Vec3(10.0 * i, 0, 0) + errs[i];
    r.p_std = Vec3(1, 2, 5);
    traj.records.push_back(r);
  }
  const EvalResult r = evaluate(truth, traj, frame);
  ASSERT_TRUE(r.has_sigma);
  EXPECT_EQ(r.sigma_epochs, 4u);
  // |e| = 1, 2, 5, 7.21 vs 3 sqrt(5) = 6.708: three of four within.
  EXPECT_DOUBLE_EQ(r.within_3sigma, 0.75);
  // NEES = dn^2/1 + de^2/4: 1, 1, 9 + 4 = 13, 36 + 4 = 40 -> mean 55/4.
  EXPECT_NEAR(r.mean_nees, 55.0 / 4.0, 1e-6);
  EXPECT_NEAR(r.series[0].sigma_h, std::sqrt(5.0), 1e-12);
}

TEST(EvalMetrics, AlignmentRemovesInitialOffsetAndHeading) {
  const earth::LocalFrame frame(kOrigin);
  // Truth: a 200 m L-shaped path. The trajectory is the same path expressed in a frame
  // rotated by -30 deg and shifted: it starts at (500, -70) heading -30 deg.
  auto path = [](double t) {
    return t <= 100 ? Vec3(t, 0, 0) : Vec3(100, t - 100, 0);
  };
  auto head = [](double t) { return t <= 100 ? 0.0 : kPi / 2; };
  const double dpsi = -30.0 * kDeg;
  const Mat3 R = rot_z(dpsi);
  const Vec3 shift(500, -70, 3);
  const auto truth = make_truth(frame, 0, 200, 1.0, path, head);
  const auto traj = make_traj(
      0, 200, 0.5, [&](double t) { return Vec3(R * path(t) + shift); },
      [&](double t) { return wrap_pi(head(t) + dpsi); });
  const EvalResult raw = evaluate(truth, traj, frame);
  EXPECT_GT(raw.max_error, 400.0);
  EXPECT_NEAR(raw.heading_rmse / kDeg, 30.0, 1e-9);

  EvalOptions o;
  o.align_origin = true;
  const EvalResult r = evaluate(truth, traj, frame, o);
  EXPECT_TRUE(r.aligned && r.align_rotated);
  EXPECT_NEAR(r.align_yaw / kDeg, 30.0, 1e-9);
  EXPECT_NEAR((r.align_offset + shift).norm(), 0.0, 1e-6);
  EXPECT_NEAR(r.max_error, 0.0, 1e-6);
  EXPECT_NEAR(r.heading_rmse, 0.0, 1e-9);
  EXPECT_NEAR(r.drift_rate, 0.0, 1e-9);
  EXPECT_NEAR(r.distance, 200.0, 1e-6);
}

TEST(EvalMetrics, LatLonTrajectoryUsesFrameAndErrorsWithoutOverlap) {
  const earth::LocalFrame frame(kOrigin);
  const auto truth = make_truth(
      frame, 100, 200, 1.0, [](double t) { return Vec3(0, t, 0); }, [](double) { return 0.0; });
  TrajectoryData traj;
  traj.file = "late.csv";
  traj.has_lla = true;
  traj.has_ned = true;
  for (int i = 0; i <= 100; ++i) {
    TrajectoryRecord r;
    r.t = 100 + i;
    r.lla = frame.geodetic_from_ned(Vec3(0.5, 100 + i, 0));
    r.p_inN = Vec3(1e6, 1e6, 0);  // another frame's numbers: lla must win
    traj.records.push_back(r);
  }
  const EvalResult r = evaluate(truth, traj, frame);
  EXPECT_NEAR(r.max_error, 0.5, 1e-6);
  EXPECT_NEAR(r.final_error, 0.5, 1e-6);

  for (auto& rec : traj.records) rec.t += 1000;
  try {
    evaluate(truth, traj, frame);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("late.csv"), std::string::npos) << msg;
    EXPECT_NE(msg.find("truth.bin"), std::string::npos) << msg;
  }
}

TEST(EvalMetrics, StreamingEvaluatorKeepsConstantMemoryAndMatchesEvaluate) {
  // 2000 s of a 200 Hz truth against a 20 Hz trajectory with a growing error, fed in step
  // as `wheelins run` does: the evaluator never holds more than the truth records between
  // two trajectory records, and its result is evaluate()'s (evaluate() is built on the
  // Evaluator, so its streamed drift curve and heading RMSE are also checked against the
  // batch drift_rate_curve() and an RMS taken from the per-epoch series).
  const earth::LocalFrame frame(kOrigin);
  auto pos = [](double t) { return Vec3(1.2 * t, 30.0 * std::sin(0.01 * t), 0.0); };
  auto err = [](double t) { return Vec3(0.001 * t, -0.0005 * t, 0.0); };
  const TruthData truth = make_truth(frame, 0.0, 2000.0, 0.005, pos, [](double t) { return 0.01 * t; });
  const TrajectoryData traj = make_traj(
      1.0, 1999.0, 0.05, [&](double t) { return Vec3(pos(t) + err(t)); },
      [](double t) { return 0.01 * t + 0.002; });
  const EvalResult batch = evaluate(truth, traj, frame);

  Evaluator::Sources src;
  src.truth_file = "truth.bin";
  src.traj_file = "traj.csv";
  src.traj_has_lla = false;
  src.traj_has_sigma = false;
  Evaluator ev(frame, src, {}, false);
  std::size_t i = 0, max_pending = 0;
  for (const TrajectoryRecord& r : traj.records) {
    while (i < truth.records.size() && truth.records[i].t < r.t) ev.add_truth(truth.records[i++]);
    ev.add_trajectory(r);
    max_pending = std::max(max_pending, ev.pending());
  }
  ev.end_trajectory();  // the last second of truth is then not held back
  while (i < truth.records.size()) {
    ev.add_truth(truth.records[i++]);
    max_pending = std::max(max_pending, ev.pending());
  }
  const EvalResult s = ev.finish();
  {
    // A trajectory going back in time is an error naming the source and the record.
    Evaluator back(frame, src, {}, false);
    back.add_trajectory(traj.records[1]);
    try {
      back.add_trajectory(traj.records[0]);
      ADD_FAILURE() << "a backwards time was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("traj.csv"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("record 1"), std::string::npos) << e.what();
    }
  }
  EXPECT_LE(max_pending, 11u);  // 0.05 s of 200 Hz truth
  EXPECT_TRUE(s.series.empty());
  EXPECT_EQ(s.epochs, batch.epochs);
  EXPECT_EQ(s.skipped_outside, batch.skipped_outside);
  EXPECT_EQ(s.skipped_outside, 400u);  // the first and the last second of the truth
  EXPECT_DOUBLE_EQ(s.drift_rate, batch.drift_rate);
  EXPECT_EQ(s.drift_curve, batch.drift_curve);
  EXPECT_DOUBLE_EQ(s.heading_rmse, batch.heading_rmse);
  EXPECT_NEAR(s.heading_rmse, 0.002, 1e-9);
  EXPECT_DOUBLE_EQ(s.max_error, batch.max_error);
  EXPECT_GT(s.drift_rate, 0.0);
  std::vector<double> dist, err_h;
  double sum_h2 = 0.0;
  for (const EpochError& e : batch.series) {
    dist.push_back(e.distance);
    err_h.push_back(e.err_h);
    sum_h2 += e.heading_err * e.heading_err;
  }
  const std::vector<double> curve = drift_rate_curve(dist, err_h, 100.0);
  ASSERT_EQ(s.drift_curve.size(), curve.size());
  ASSERT_GT(curve.size(), 10u);
  for (std::size_t k = 0; k < curve.size(); ++k) EXPECT_DOUBLE_EQ(s.drift_curve[k], curve[k]) << k;
  EXPECT_NEAR(s.heading_rmse, std::sqrt(sum_h2 / static_cast<double>(batch.series.size())), 1e-15);
}
