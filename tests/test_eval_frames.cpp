// Frames and alignment of `wheelins evaluate`: TUM files in ENU and NED, their header lines,
// the refusal of a mirrored (ENU read as NED) trajectory, and the whole-trajectory SE(3) and
// SE(2) fits named as evo names them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "io_test_util.hpp"
#include "wheelins/eval/metrics.hpp"
#include "wheelins/eval/rigid_fit.hpp"
#include "wheelins/io/trajectory.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/nav/types.hpp"

using namespace wheelins;
using namespace wheelins::iotest;

namespace {

const earth::Geodetic kOrigin{30.5 * kDeg, 114.3 * kDeg, 20.0};

// A drive with turns both ways (a figure of eight of radius 40 m at 5 m/s): its mirror image
// turns the other way round, which no rotation can undo.
Vec3 eight(double t) {
  const double w = 5.0 / 40.0;
  return Vec3(40.0 * std::sin(w * t), 20.0 * std::sin(2.0 * w * t), 0.3 * std::sin(0.05 * t));
}
double eight_heading(double t) {
  const double h = 1e-3;
  const Vec3 d = eight(t + h) - eight(t - h);
  return std::atan2(d.y(), d.x());
}

// The figure of eight as the truth, 150 s every dt.
TruthData truth_of(const earth::LocalFrame& frame, double dt) {
  TruthData d;
  d.file = "truth.bin";
  d.records.resize(static_cast<std::size_t>(std::llround(150.0 / dt)) + 1);
  for (std::size_t i = 0; i < d.records.size(); ++i) {
    TruthRecord& r = d.records[i];
    r.t = dt * static_cast<double>(i);
    r.lla = frame.geodetic_from_ned(eight(r.t));
    r.rpy.z() = eight_heading(r.t);
  }
  return d;
}

// The trajectory: the truth plus an east error growing 1 cm per second (1.5 m at the end).
std::vector<TrajectoryRecord> drifted(const std::function<Vec3(const Vec3&)>& move = {}) {
  std::vector<TrajectoryRecord> v;
  for (int i = 0; i <= 1500; ++i) {
    TrajectoryRecord r;
    r.t = 0.1 * i;
    r.p_inN = eight(r.t) + Vec3(0.0, 0.01 * r.t, 0.0);
    if (move) r.p_inN = move(r.p_inN);
    r.rpy = Vec3(0.01, -0.02, eight_heading(r.t));
    v.push_back(r);
  }
  return v;
}

void write_tum(const std::filesystem::path& file, const std::vector<TrajectoryRecord>& recs, TumFrame f,
               bool header) {
  TrajectoryWriterOptions o;
  o.tum_frame = f;
  o.origin = kOrigin;
  auto w = make_trajectory_writer(TrajectoryFormat::kTum, file, o);
  for (const auto& r : recs) w->write(r);
  w->commit();
  if (header) return;
  // What ROS tools and evo write: the records only.
  std::string text = read_text_file(file), body;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    const std::string line = text.substr(pos, end - pos + 1);
    if (line[0] != '#') body += line;
    pos = end + 1;
  }
  write_text(file, body);
}

}  // namespace

TEST(TumFrames, EnuFileRoundTripsThroughItsHeader) {
  ScratchDir dir;
  const auto recs = drifted();
  write_tum(dir / "enu.tum", recs, TumFrame::kEnu, true);
  const std::string text = read_text_file(dir / "enu.tum");
  EXPECT_HAS(text, "# frame: enu");
  EXPECT_HAS(text, "# origin: 30.5 114.3 20 ");
  // The first record in ENU: x east, y north, z up.
  const TrajectoryData d = read_trajectory(dir / "enu.tum");
  EXPECT_EQ(d.tum_frame, TumFrame::kEnu);
  EXPECT_FALSE(d.frame_assumed);
  ASSERT_TRUE(d.origin.has_value());
  EXPECT_NEAR(d.origin->lat / kDeg, 30.5, 1e-12);
  ASSERT_EQ(d.records.size(), recs.size());
  for (std::size_t i = 0; i < recs.size(); i += 100) {
    EXPECT_LT((d.records[i].p_inN - recs[i].p_inN).norm(), 1e-9);
    EXPECT_LT((d.records[i].rpy - recs[i].rpy).norm(), 1e-9) << i;
  }
  std::FILE* f = std::fopen((dir / "enu.tum").c_str(), "r");
  ASSERT_NE(f, nullptr);
  char line[256];
  double v[8];
  do {
    ASSERT_NE(std::fgets(line, sizeof line, f), nullptr);
  } while (line[0] == '#');
  std::fclose(f);
  ASSERT_EQ(std::sscanf(line, "%lf %lf %lf %lf %lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7]),
            8);
  EXPECT_NEAR(v[1], recs[0].p_inN.y(), 1e-9);   // east
  EXPECT_NEAR(v[2], recs[0].p_inN.x(), 1e-9);   // north
  EXPECT_NEAR(v[3], -recs[0].p_inN.z(), 1e-9);  // up

  // A frame asked for against the file's own line is an error naming the line.
  TrajectoryReadOptions ned;
  ned.tum_frame = TumFrame::kNed;
  const std::string e = error_of([&] { read_trajectory(dir / "enu.tum", TrajectoryFormat::kAuto, ned); });
  EXPECT_HAS(e, "line 1");
  EXPECT_HAS(e, "says its frame is enu, but ned was given");
  // A frame for a format that has none.
  write_text(dir / "t.csv", "t_s,north_m,east_m,down_m\n0,0,0,0\n");
  EXPECT_HAS(error_of([&] { read_trajectory(dir / "t.csv", TrajectoryFormat::kAuto, ned); }), "is for a TUM trajectory");
  // A garbled frame line.
  write_text(dir / "bad.tum", "# frame: nwu\n0 0 0 0 0 0 0 1\n");
  EXPECT_HAS(error_of([&] { read_trajectory(dir / "bad.tum"); }), "frame 'nwu'");
}

// The defect: an ENU trajectory (as ROS and evo write it, no header) read as NED was scored
// silently as a huge drift. Now it is refused with the frame to give; with the frame it
// scores as the same trajectory in NED does.
TEST(TumFrames, EnuTrajectoryIsScoredRightWithItsFrameAndRefusedWithout) {
  ScratchDir dir;
  const earth::LocalFrame frame(kOrigin);
  const TruthData truth = truth_of(frame, 0.1);
  const auto recs = drifted();
  write_tum(dir / "ned.tum", recs, TumFrame::kNed, true);
  write_tum(dir / "enu.tum", recs, TumFrame::kEnu, false);
  const eval::EvalResult ned = eval::evaluate(truth, read_trajectory(dir / "ned.tum"), frame);
  EXPECT_NEAR(ned.final_error, 1.5, 0.01);

  const TrajectoryData assumed = read_trajectory(dir / "enu.tum");
  EXPECT_TRUE(assumed.frame_assumed);
  EXPECT_EQ(assumed.tum_frame, TumFrame::kNed);
  const std::string e = error_of([&] { eval::evaluate(truth, assumed, frame); });
  EXPECT_HAS(e, "mirror image of the truth's");
  EXPECT_HAS(e, "--frame enu");
  EXPECT_HAS(e, "no frame line");

  TrajectoryReadOptions enu;
  enu.tum_frame = TumFrame::kEnu;
  const eval::EvalResult r = eval::evaluate(truth, read_trajectory(dir / "enu.tum", TrajectoryFormat::kAuto, enu), frame);
  EXPECT_NEAR(r.rms_error, ned.rms_error, 1e-6);
  EXPECT_NEAR(r.drift_rate, ned.drift_rate, 1e-9);
  EXPECT_NEAR(r.heading_rmse, ned.heading_rmse, 1e-9);
}

TEST(TumFrames, MirrorCheckLeavesDriftAndRotationAlone) {
  std::vector<Vec3> a, b, mirrored, turned, line, line_mirrored;
  for (int i = 0; i <= 300; ++i) {
    const double t = 0.5 * i;
    b.push_back(eight(t));
    a.push_back(eight(t) + Vec3(0.0, 0.02 * t, 0.0));  // 3 m of drift
    mirrored.push_back(Vec3(a.back().y(), a.back().x(), -a.back().z()));
    turned.push_back(rot_z(2.0) * a.back() + Vec3(100, -50, 3));
    line.push_back(Vec3(t, 0.5 * t, 0.0));
    line_mirrored.push_back(Vec3(0.5 * t, t, 0.0));
  }
  EXPECT_FALSE(eval::check_mirror(a, b).mirrored);
  EXPECT_FALSE(eval::check_mirror(turned, b).mirrored);
  const eval::MirrorCheck m = eval::check_mirror(mirrored, b);
  EXPECT_TRUE(m.mirrored);
  EXPECT_LT(m.reflection_rms, 3.0);
  EXPECT_GT(m.rotation_rms, 10.0);
  // A straight line is its own mirror image: no verdict.
  EXPECT_FALSE(eval::check_mirror(line_mirrored, line).mirrored);
}

// --align (evo's SE(3) Umeyama) undoes any rotation and shift; --align-se2 one about the
// vertical; --align-origin (evo's --align_origin) only what the first epoch shows.
TEST(TumFrames, WholeTrajectoryAlignmentsUndoARigidMotion) {
  const earth::LocalFrame frame(kOrigin);
  const TruthData truth = truth_of(frame, 0.1);
  TrajectoryData plain;
  plain.file = "traj.tum";
  plain.format = TrajectoryFormat::kTum;
  plain.has_ned = plain.has_heading = plain.has_roll_pitch = true;
  plain.records = drifted();
  const eval::EvalResult base = eval::evaluate(truth, plain, frame);

  // Turned about the vertical by 25 deg and shifted: SE(2) and SE(3) recover the same figures
  // as the unmoved trajectory aligned the same way.
  const Mat3 Rz = rot_z(25.0 * kDeg);
  TrajectoryData yawed = plain;
  yawed.records = drifted([&](const Vec3& p) { return Vec3(Rz * p + Vec3(30, -12, 2)); });
  for (auto& r : yawed.records) r.rpy.z() = wrap_pi(r.rpy.z() + 25.0 * kDeg);
  EXPECT_GT(eval::evaluate(truth, yawed, frame).rms_error, 20.0);
  eval::EvalOptions se2;
  se2.align_fit = eval::AlignFit::kSe2;
  const eval::EvalResult s2 = eval::evaluate(truth, yawed, frame, se2);
  const eval::EvalResult s2_base = eval::evaluate(truth, plain, frame, se2);
  EXPECT_EQ(s2.align_method, "se2");
  // (to 1e-4 deg: the errors are scored in each truth point's own north/east/down, which turn
  // with the earth's curvature over the track, 3e-5 deg here, while the fit is in one frame)
  EXPECT_NEAR(wrap_pi(s2.align_yaw - s2_base.align_yaw) / kDeg, -25.0, 1e-4);
  EXPECT_NEAR(s2.rms_error, s2_base.rms_error, 1e-6);
  EXPECT_NEAR(s2.heading_rmse, s2_base.heading_rmse, 1e-6);
  EXPECT_LT(s2.rms_error, base.rms_error);  // the fit also takes out the drift's mean
  EXPECT_NEAR(s2.align_residual, s2.rms_error, 0.5);

  // Tilted as well (a 3-D rotation): SE(3) undoes it, SE(2) cannot.
  const Mat3 R = rot_z(-40.0 * kDeg) * Eigen::AngleAxisd(20.0 * kDeg, Vec3::UnitX()).toRotationMatrix();
  TrajectoryData tilted = plain;
  tilted.records = drifted([&](const Vec3& p) { return Vec3(R * p + Vec3(-5, 8, 1)); });
  eval::EvalOptions se3;
  se3.align_fit = eval::AlignFit::kSe3;
  const eval::EvalResult s3 = eval::evaluate(truth, tilted, frame, se3);
  const eval::EvalResult s3_base = eval::evaluate(truth, plain, frame, se3);
  EXPECT_EQ(s3.align_method, "se3");
  EXPECT_NEAR(s3.rms_error, s3_base.rms_error, 1e-3);
  // The fit is the inverse of the motion (up to what the drift pulls it by).
  EXPECT_LT((dcm_from_euler(s3.align_rpy) - dcm_from_euler(s3_base.align_rpy) * R.transpose()).norm(), 1e-3);
  EXPECT_GT(eval::evaluate(truth, tilted, frame, se2).rms_error, s3.rms_error + 0.3);
  EXPECT_HAS(eval::to_json(s3), "\"align_method\": \"se3\"");

  // Two alignments at once are an error.
  eval::EvalOptions both = se3;
  both.align_origin = true;
  EXPECT_HAS(error_of([&] { eval::evaluate(truth, plain, frame, both); }), "two alignments");
}
