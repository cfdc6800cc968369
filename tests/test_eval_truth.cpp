// Evaluation against truth without heading (the course), the final error over distance,
// the antenna lever arm, the truth time offset, the truth quality checks and the streaming
// run evaluation of a text truth, on synthetic drives with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "io_test_util.hpp"
#include "wheelins/eval/metrics.hpp"
#include "wheelins/eval/run_evaluation.hpp"
#include "wheelins/eval/truth_quality.hpp"
#include "wheelins/nav/types.hpp"

using namespace wheelins;
using namespace wheelins::eval;
using iotest::error_of;

namespace {

const earth::Geodetic kOrigin{30.5 * kDeg, 114.3 * kDeg, 20.0};

// Positions-only truth (a GNSS track) from t -> ned.
TruthData track(const earth::LocalFrame& frame, double t0, double t1, double dt,
                const std::function<Vec3(double)>& pos) {
  TruthData d;
  d.file = "track.csv";
  d.layout = TruthLayout::kText;
  d.has_velocity = d.has_attitude = false;
  const int n = static_cast<int>(std::llround((t1 - t0) / dt));
  for (int i = 0; i <= n; ++i) {
    TruthRecord r;
    r.t = t0 + i * dt;
    r.lla = frame.geodetic_from_ned(pos(r.t));
    d.records.push_back(r);
  }
  return d;
}

TrajectoryData traj_of(double t0, double t1, double dt, const std::function<Vec3(double)>& pos,
                       const std::function<Vec3(double)>& rpy) {
  TrajectoryData d;
  d.file = "traj.csv";
  d.has_ned = d.has_heading = d.has_roll_pitch = true;
  const int n = static_cast<int>(std::llround((t1 - t0) / dt));
  for (int i = 0; i <= n; ++i) {
    TrajectoryRecord r;
    r.t = t0 + i * dt;
    r.p_inN = pos(r.t);
    r.lla = earth::LocalFrame(kOrigin).geodetic_from_ned(r.p_inN);  // (used where has_lla)
    r.rpy = rpy(r.t);
    d.records.push_back(r);
  }
  return d;
}

// A right-hand circle of radius 50 m at 5 m/s (yaw rate 0.1 rad/s), heading = yaw rate * t.
constexpr double kRadius = 50.0, kSpeed = 5.0, kYawRate = kSpeed / kRadius;
Vec3 circle(double t) {
  const double psi = kYawRate * t;
  return Vec3(kRadius * std::sin(psi), kRadius * (1.0 - std::cos(psi)), 0.0);
}
double circle_heading(double t) { return wrap_pi(kYawRate * t); }

}  // namespace

// The truth is a 5 Hz position track; the trajectory's heading is 2 deg off the direction it
// drives. The course over a centred 1 s chord of a circle is its tangent: the error measured
// is the 2 deg, with the source said to be the course.
TEST(EvalTruth, HeadingFromTheCourseMeasuresAKnownHeadingError) {
  const earth::LocalFrame frame(kOrigin);
  const TruthData truth = track(frame, 0.0, 60.0, 0.2, circle);
  const TrajectoryData traj = traj_of(0.0, 60.0, 0.02, circle,
                                      [](double t) { return Vec3(0, 0, wrap_pi(circle_heading(t) + 2.0 * kDeg)); });
  const EvalResult r = evaluate(truth, traj, frame);
  EXPECT_EQ(r.heading_source, "course");
  ASSERT_TRUE(r.has_heading);
  EXPECT_NEAR(r.heading_rmse / kDeg, 2.0, 1e-3);
  EXPECT_NEAR(r.heading_max_abs / kDeg, 2.0, 1e-3);
  EXPECT_NEAR(r.series[100].heading_err / kDeg, 2.0, 1e-3);  // sign: trajectory - course
  // Every epoch but the three at each end: no fix B/2 = 0.5 s beyond them.
  EXPECT_EQ(r.epochs, 301u);
  EXPECT_EQ(r.heading_epochs, 301u - 2u * 3u);
  EXPECT_NE(to_json(r).find("\"heading_source\": \"course\""), std::string::npos);

  // A longer baseline is still the tangent on a circle.
  EvalOptions o;
  o.course_baseline = 3.0;
  EXPECT_NEAR(evaluate(truth, traj, frame, o).heading_rmse / kDeg, 2.0, 1e-3);

  // Standing still for the first 20 s, then driving: no course (and no heading error) while
  // the truth moves slower than 1 m/s.
  auto stop_go = [](double t) { return t < 20.0 ? circle(0.0) : circle(t - 20.0); };
  const TruthData t2 = track(frame, 0.0, 60.0, 0.2, stop_go);
  const TrajectoryData j2 = traj_of(0.0, 60.0, 0.02, stop_go, [](double t) {
    return Vec3(0, 0, wrap_pi((t < 20.0 ? 0.0 : circle_heading(t - 20.0)) - 1.0 * kDeg));
  });
  const EvalResult r2 = evaluate(t2, j2, frame);
  EXPECT_NEAR(r2.heading_rmse / kDeg, 1.0, 2e-3);
  // The repeated fix is a stall: no course across it. From t = 20.8 s (the first fix 0.5 s
  // after the stall ends is 20.2 s) to 59.4 s.
  EXPECT_EQ(r2.truth_quality.stall_count, 1u);
  EXPECT_EQ(r2.heading_epochs, 194u);
  for (const EpochError& e : r2.series) {
    if (e.t < 19.4) {
      EXPECT_TRUE(std::isnan(e.heading_err)) << e.t;
    }
  }

  // Truth with attitude keeps using it: the source is the truth.
  TruthData with_att = truth;
  with_att.has_attitude = true;
  for (auto& rec : with_att.records) rec.rpy.z() = circle_heading(rec.t);
  const EvalResult r3 = evaluate(with_att, traj, frame);
  EXPECT_EQ(r3.heading_source, "truth");
  EXPECT_EQ(r3.heading_epochs, 301u);
  EXPECT_NEAR(r3.heading_rmse / kDeg, 2.0, 1e-9);
}

// Straight north 300 m; the error grows to 3 m at the end: 1 % of the distance.
TEST(EvalTruth, FinalErrorOverDistance) {
  const earth::LocalFrame frame(kOrigin);
  const TruthData truth = track(frame, 0.0, 60.0, 0.2, [](double t) { return Vec3(5.0 * t, 0, 0); });
  const TrajectoryData traj = traj_of(
      0.0, 60.0, 0.1, [](double t) { return Vec3(5.0 * t, 0.05 * t, 0); }, [](double) { return Vec3::Zero(); });
  const EvalResult r = evaluate(truth, traj, frame);
  EXPECT_NEAR(r.distance, 300.0, 1e-6);
  EXPECT_NEAR(r.final_error, 3.0, 1e-6);
  EXPECT_NEAR(r.final_error_ratio, 0.01, 1e-8);
  const std::string json = to_json(r);
  const auto k = json.find("\"final_error_over_distance_pct\": ");
  ASSERT_NE(k, std::string::npos) << json;
  EXPECT_NEAR(std::strtod(json.c_str() + k + 32, nullptr), 1.0, 1e-8) << json;
  // Without distance it is undefined, not infinite.
  const TruthData still = track(frame, 0.0, 10.0, 0.2, [](double) { return Vec3::Zero(); });
  const TrajectoryData near = traj_of(
      0.0, 10.0, 0.1, [](double) { return Vec3(1, 0, 0); }, [](double) { return Vec3::Zero(); });
  EXPECT_TRUE(std::isnan(evaluate(still, near, frame).final_error_ratio));
}

// A circle driven with the antenna 1.5 m ahead, 0.3 m right and 1.2 m above the reference
// point, rolled 3 deg and pitched -2 deg: the truth is the antenna's track. With the lever
// arm the error is nil; without it, it is the lever arm's horizontal length. The antenna's
// track is a circle too, whose tangent leads the heading by atan2(a_x, R - a_y) (a the
// levelled lever arm); the evaluation takes that off.
TEST(EvalTruth, AntennaLeverArm) {
  const earth::LocalFrame frame(kOrigin);
  const Vec3 lever(1.5, 0.3, -1.2);
  auto rpy = [](double t) { return Vec3(3.0 * kDeg, -2.0 * kDeg, circle_heading(t)); };
  auto antenna = [&](double t) { return Vec3(circle(t) + dcm_from_euler(rpy(t)) * lever); };
  const TruthData truth = track(frame, 0.0, 60.0, 0.2, antenna);
  const TrajectoryData traj = traj_of(0.0, 60.0, 0.02, circle, rpy);

  EvalOptions o;
  o.antenna = lever;
  const EvalResult with = evaluate(truth, traj, frame, o);
  EXPECT_LT(with.max_error, 1e-3);  // the trajectory's linear interpolation over 0.02 s: ~1e-5 m
  EXPECT_NEAR(with.heading_rmse / kDeg, 0.0, 0.005);
  EXPECT_EQ(with.antenna, lever);
  const EvalResult without = evaluate(truth, traj, frame);
  const Vec3 a = dcm_from_euler(Vec3(3.0 * kDeg, -2.0 * kDeg, 0.0)) * lever;  // levelled
  EXPECT_NEAR(a.head<2>().norm(), 1.58, 0.01);
  EXPECT_NEAR(without.rms_error, a.head<2>().norm(), 1e-3);
  EXPECT_NEAR(without.max_error, a.head<2>().norm(), 1e-3);
  // The antenna's course leads by atan2(a_x, R - a_y) = 1.78 deg in this right turn.
  const double lead = std::atan2(a.x(), kRadius - a.y());
  EXPECT_NEAR(lead / kDeg, 1.78, 0.01);
  EXPECT_NEAR(without.heading_rmse, lead, 1e-5);
  // Heading only (no roll/pitch in the trajectory): the lever arm is turned by the heading alone.
  TrajectoryData flat = traj;
  flat.has_roll_pitch = false;
  for (auto& rec : flat.records) {
    rec.rpy.x() = std::nan("");  // not read
    rec.rpy.y() = 0.0;
  }
  const TruthData flat_truth = track(frame, 0.0, 60.0, 0.2, [&](double t) {
    return Vec3(circle(t) + rot_z(circle_heading(t)) * lever);
  });
  EXPECT_LT(evaluate(flat_truth, flat, frame, o).max_error, 1e-3);
  // A lever arm needs the trajectory's heading.
  TrajectoryData headless = traj;
  headless.has_heading = false;
  EXPECT_NE(error_of([&] { evaluate(truth, headless, frame, o); }).find("heading"), std::string::npos);
}

TEST(EvalTruth, TruthTimeOffset) {
  const earth::LocalFrame frame(kOrigin);
  // The truth's clock is 100 s behind the trajectory's.
  TruthData truth = track(frame, 0.0, 60.0, 0.2, [](double t) { return Vec3(5.0 * t, 0, 0); });
  for (auto& r : truth.records) r.t -= 100.0;
  const TrajectoryData traj = traj_of(
      0.0, 60.0, 0.1, [](double t) { return Vec3(5.0 * t, 0, 0); }, [](double) { return Vec3::Zero(); });
  EXPECT_NE(error_of([&] { evaluate(truth, traj, frame); }).find("no truth epoch"), std::string::npos);
  EvalOptions o;
  o.truth_time_offset = 100.0;
  const EvalResult r = evaluate(truth, traj, frame, o);
  EXPECT_EQ(r.epochs, 301u);
  EXPECT_LT(r.max_error, 1e-6);
  EXPECT_EQ(r.truth_time_offset, 100.0);
  EXPECT_NEAR(r.t_start, 0.0, 1e-9);
  // 0.5 s off: 2.5 m behind.
  o.truth_time_offset = 100.5;
  EXPECT_NEAR(evaluate(truth, traj, frame, o).max_error, 2.5, 1e-6);
}

// A 5 Hz track north at 10 m/s with a 4 s gap, a fix thrown 60 m east (a jump by speed), a fix
// 2 m to the side (a jump by acceleration only: 14 m/s but ~70 m/s^2) and a step of 30 m east
// after which the track stays shifted.
TEST(EvalTruth, TruthQualityChecksReportAndLeaveOutBadFixes) {
  const earth::LocalFrame frame(kOrigin);
  TruthData truth;
  truth.file = "bad.csv";
  truth.has_velocity = truth.has_attitude = false;
  std::vector<double> times;
  for (int i = 0; i <= 300; ++i) {
    const double t = 0.2 * i;
    if (t > 20.1 && t < 23.9) continue;  // the gap: 20.0 .. 24.0
    times.push_back(t);
  }
  auto true_pos = [](double t) { return Vec3(10.0 * t, 0, 0); };
  for (double t : times) {
    Vec3 p = true_pos(t);
    if (std::abs(t - 10.0) < 1e-9) p.y() += 60.0;   // speed jump
    if (std::abs(t - 30.0) < 1e-9) p.y() += 2.0;    // acceleration jump
    if (t > 49.9) p.y() += 30.0;                    // a step at t = 50
    TruthRecord r;
    r.t = t;
    r.lla = frame.geodetic_from_ned(p);
    truth.records.push_back(r);
  }
  const TruthQualityReport q = check_truth_quality(truth);
  EXPECT_EQ(q.records, truth.records.size());
  EXPECT_EQ(q.gap_count, 1u);
  EXPECT_EQ(q.stall_count, 0u);
  ASSERT_EQ(q.gaps.size(), 1u);
  EXPECT_NEAR(q.gaps[0].t_from, 20.0, 1e-9);
  EXPECT_NEAR(q.gaps[0].t_to, 24.0, 1e-9);
  EXPECT_NEAR(q.gap_seconds, 4.0, 1e-9);
  EXPECT_NEAR(q.gap_distance, 40.0, 1e-3);
  EXPECT_NEAR(q.median_interval, 0.2, 1e-9);
  ASSERT_EQ(q.jump_count, 3u);
  ASSERT_EQ(q.jumps.size(), 3u);
  EXPECT_NEAR(q.jumps[0].t, 10.0, 1e-9);
  EXPECT_GT(q.jumps[0].speed, 70.0);
  EXPECT_NEAR(q.jumps[1].t, 30.0, 1e-9);
  EXPECT_LT(q.jumps[1].speed, 70.0);
  EXPECT_GT(q.jumps[1].accel, 3.0 * 9.80665);
  EXPECT_NEAR(q.jumps[2].t, 50.0, 1e-9);
  EXPECT_EQ(q.bad_records, 3u);
  const std::string text = describe_truth_quality(q);
  EXPECT_NE(text.find("gap   20.000 .. 24.000 s"), std::string::npos) << text;
  EXPECT_NE(text.find("jump  at 10.000 s"), std::string::npos) << text;

  // The evaluation of a trajectory on the true path (shifted like the truth after the step):
  // the three jumped fixes are left out and counted; the distance does not count the jumps
  // (60 m there and back, 2 m there and back, the 30 m step).
  const TrajectoryData traj = traj_of(
      0.0, 60.0, 0.05, [&](double t) { return Vec3(true_pos(t) + Vec3(0, t >= 50.0 ? 30.0 : 0.0, 0)); },
      [](double) { return Vec3::Zero(); });
  const EvalResult r = evaluate(truth, traj, frame);
  EXPECT_EQ(r.skipped_truth_jump, 3u);
  EXPECT_EQ(r.epochs, truth.records.size() - 3u);
  EXPECT_EQ(r.truth_quality.jump_count, 3u);
  // 600 m driven, less the 2 m between the last good fix and the jumped fix of the step
  // (the distance follows the good fixes, and the step is taken from the jumped fix on).
  EXPECT_NEAR(r.distance, 598.0, 1e-3);
  EXPECT_LT(r.max_error, 0.6);  // the interpolation across the step of the trajectory itself
  const std::string json = to_json(r);
  EXPECT_NE(json.find("\"skipped_truth_jump\": 3"), std::string::npos) << json;
  EXPECT_NE(json.find("\"gaps\": [{\"t_from_s\": 20, \"t_to_s\": 24"), std::string::npos) << json;
  // No course across the gap: the epochs within 0.5 s of it have no heading error.
  for (const EpochError& e : r.series) {
    if (e.t > 19.7 && e.t < 24.3) {
      EXPECT_TRUE(std::isnan(e.heading_err)) << e.t;
    }
  }
}

// Repeated fixes: a vehicle standing still by its own velocity is not counted; a receiver
// repeating its fix while moving is a stall; denser than 0.05 s only the speed is judged.
TEST(EvalTruth, RepeatedFixesStandingAndStalls) {
  const earth::LocalFrame frame(kOrigin);
  TruthQualityMonitor standing;
  for (int i = 0; i < 400; ++i) standing.add(0.005 * i, Vec3::Zero(), 0.0);
  EXPECT_EQ(standing.report().repeated, 0u);
  EXPECT_TRUE(standing.report().clean());

  TruthQualityMonitor unknown;  // no velocity: a 2 s run of one fix at 200 Hz is a stall
  for (int i = 0; i < 400; ++i) unknown.add(0.005 * i, Vec3(i < 100 ? 0.005 * i : 0.5, 0, 0), std::nan(""));
  unknown.add(2.0, Vec3(10.0, 0, 0), std::nan(""));  // caught up: 9.5 m in 1.5 s from its first record
  EXPECT_EQ(unknown.report().repeated, 299u);
  EXPECT_EQ(unknown.report().stall_count, 1u);
  EXPECT_EQ(unknown.report().jump_count, 0u);
  ASSERT_EQ(unknown.report().gaps.size(), 1u);
  EXPECT_NEAR(unknown.report().gaps[0].t_from, 0.5, 1e-9);
  EXPECT_EQ(unknown.report().gaps[0].repeated, 299u);

  // 1 mm of noise at 200 Hz is 0.4 m/s between records and ~100 m/s^2: not a jump there.
  TruthQualityMonitor dense;
  for (int i = 0; i < 2000; ++i) dense.add(0.005 * i, Vec3(0.01 * i, (i % 2) * 0.001, 0), 2.0);
  EXPECT_TRUE(dense.report().clean());
  EXPECT_THROW(TruthQualityMonitor(TruthQualityOptions{0.5, 70.0, 30.0, 0.05}), InputError);
}

// `wheelins run`'s streaming evaluation reads a GNSS CSV truth too (time scale, antenna, time
// offset), with the same result as evaluate() on the whole file and a bounded number of
// truth records held.
TEST(EvalTruth, RunEvaluationStreamsATextTruth) {
  iotest::ScratchDir dir;
  const earth::LocalFrame frame(kOrigin);
  const Vec3 lever(1.0, 0.0, -1.5);
  // GNSS at 5 Hz, logged at 100 Hz with its Timestamp in tenths of a second; its clock
  // 1000 s behind the vehicle's.
  std::string csv = "Timestamp,Lat_GNSS,Long_GNSS,Height_GNSS\n";
  for (int row = 0; row <= 6000; ++row) {
    const double t_fix = 0.2 * (row / 20);
    const earth::Geodetic g = frame.geodetic_from_ned(circle(t_fix) + rot_z(circle_heading(t_fix)) * lever);
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.1f,%.10f,%.10f,%.4f\n", 0.1 * row, g.lat / kDeg, g.lon / kDeg, g.h);
    csv += buf;
  }
  iotest::write_text(dir / "GNSS.csv", csv);
  RunEvaluationOptions o;
  o.truth.time_scale = 0.1;
  o.eval.antenna = lever;
  o.eval.truth_time_offset = 1000.0;
  RunEvaluation run(dir / "GNSS.csv", kOrigin, o);
  EXPECT_EQ(run.truth().layout(), TruthLayout::kText);
  const TrajectoryData traj = traj_of(
      1000.0, 1060.0, 0.05, [](double t) { return circle(t - 1000.0); },
      [](double t) { return Vec3(0, 0, wrap_pi(circle_heading(t - 1000.0) + 0.5 * kDeg)); });
  for (const TrajectoryRecord& r : traj.records) run.add(r);
  const EvalResult s = run.finish();
  EXPECT_EQ(s.truth_layout, "text");
  EXPECT_EQ(s.heading_source, "course");
  EXPECT_EQ(s.truth_records, 301u);
  EXPECT_EQ(s.epochs, 301u);
  // The lever arm turned with the trajectory's heading, 0.5 deg off: 1 m x sin(0.5 deg).
  EXPECT_NEAR(s.max_error, std::sin(0.5 * kDeg), 2e-4);
  EXPECT_NEAR(s.heading_rmse / kDeg, 0.5, 0.005);

  TrajectoryData with_lla = traj;
  with_lla.has_lla = true;
  const TruthData truth = read_truth(dir / "GNSS.csv", TruthLayout::kAuto, o.truth);
  const EvalResult b = evaluate(truth, with_lla, earth::LocalFrame(kOrigin), o.eval);
  EXPECT_EQ(b.epochs, s.epochs);
  EXPECT_DOUBLE_EQ(b.heading_rmse, s.heading_rmse);
  EXPECT_DOUBLE_EQ(b.max_error, s.max_error);
  EXPECT_EQ(b.drift_curve, s.drift_curve);

  // The streaming evaluator holds the records of half a course baseline and of one
  // trajectory interval, not the file.
  Evaluator::Sources src;
  src.truth_file = "GNSS.csv";
  src.traj_file = "traj";
  src.truth_has_attitude = src.truth_has_velocity = false;
  src.traj_has_lla = false;
  src.traj_has_sigma = false;
  Evaluator ev(frame, src, o.eval, false);
  std::size_t i = 0, most = 0;
  for (const TrajectoryRecord& r : traj.records) {
    while (i < truth.records.size() && truth.records[i].t + o.eval.truth_time_offset < r.t)
      ev.add_truth(truth.records[i++]);
    ev.add_trajectory(r);
    most = std::max(most, ev.pending());
  }
  ev.end_trajectory();
  while (i < truth.records.size()) ev.add_truth(truth.records[i++]);
  EXPECT_LE(most, 5u);
  EXPECT_EQ(ev.finish().epochs, s.epochs);
}
