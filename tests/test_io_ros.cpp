// ROS recordings in: bags made here from a simulated dataset (ROS 1 with the ROS bag
// storage library, ROS 2 sqlite3 and MCAP with the test-side writers of tests/ros/)
// import to the simulated files, and a run on the imported dataset gives the run on the
// original; bad recordings give InputErrors naming file, topic and message.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "io_test_util.hpp"
#include "ros/bag_writers.hpp"
#include "wheelins/io/binary.hpp"
#include "wheelins/io/manifest.hpp"
#include "wheelins/io/ros/cdr.hpp"
#include "wheelins/io/ros/import.hpp"
#include "wheelins/io/ros/mcap.hpp"
#include "wheelins/io/ros/ros1_bag.hpp"
#include "wheelins/io/truth.hpp"
#include "wheelins/run/presets.hpp"
#include "wheelins/run/ros_dataset.hpp"
#include "wheelins/run/run.hpp"
#include "wheelins/sim/simulator.hpp"
#include "wheelins/survey/dataset.hpp"

using namespace wheelins;
using namespace wheelins::test_ros;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("wheelins_test_ros_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

std::vector<std::vector<double>> rows(const fs::path& f, int ncols) {
  BinaryRowReader r(f, ncols);
  std::vector<std::vector<double>> out;
  while (const double* v = r.next()) out.emplace_back(v, v + ncols);
  return out;
}

ros::Stamp stamp_ns(std::int64_t ns) {
  return ros::Stamp{ns / 1000000000, static_cast<std::uint32_t>(ns % 1000000000)};
}
std::int64_t ns_of(double t) { return std::llround(t * 1e9); }

/// The import with its drafted manifest (what `wheelins import` does).
ros::ImportResult import_dataset(const fs::path& rec, const fs::path& out, const ros::ImportOptions& o) {
  RosDatasetOptions d;
  d.import = o;
  return import_ros_dataset(rec, out, d).import;
}

const Mat3 kEnuToNed = (Mat3() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
const Mat3 kFrdToFlu = Vec3(1, -1, -1).asDiagonal();

std::array<double, 4> xyzw(const Quat& q) { return {q.x(), q.y(), q.z(), q.w()}; }

struct Topic {
  std::string module, topic, frame;
};
const std::vector<Topic> kTopics = {{"left-C1", "/left_wheel/imu", "left_wheel_imu"},
                                    {"right-C1", "/right_wheel/imu", "right_wheel_imu"},
                                    {"body-C1", "/body/imu", "body_imu"}};
constexpr std::int64_t kReceiveDelay = 1000000;  // receive = stamp + 1 ms

/// A small simulated triple dataset (one chip per module) in `dir`.
void simulate_small(const fs::path& dir, double static_s, double duration_s) {
  sim::SimConfig cfg;
  cfg.static_duration = static_s;
  cfg.duration = duration_s;
  cfg.loop_scale = 0.25;
  cfg.path_sigma = 1.5;
  cfg.chips = 1;
  cfg.write_ideal = false;
  sim::Simulation(cfg).write(dir, false, false);
}

class RosImport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dataset_ = new fs::path(scratch("sim"));
    simulate_small(*dataset_, 2.0, 10.0);
    manifest_ = new Manifest(load_manifest(*dataset_ / "manifest.yaml", {}));
    msgs_ = new std::vector<OutMessage>(messages(*manifest_));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dataset_, ec);
    delete dataset_;
    delete manifest_;
    delete msgs_;
  }

  /// The dataset as ROS messages in receive-time order: the IMUs, the truth as
  /// nav_msgs/Odometry in ENU/FLU about the manifest's origin, the odometer speed, and
  /// /tf_static with the modules' positions.
  static std::vector<OutMessage> messages(const Manifest& m, const std::vector<Topic>& topics = kTopics) {
    std::vector<OutMessage> out;
    for (const Topic& t : topics) {
      for (const auto& r : rows(m.resolve(m.find(t.module)->file), 7)) {
        OutMessage o;
        o.topic = t.topic;
        o.kind = ros::MessageKind::kImu;
        o.imu.stamp = stamp_ns(ns_of(r[0]));
        o.receive_ns = o.imu.stamp.ns() + kReceiveDelay;
        o.imu.frame_id = t.frame;
        o.imu.gyro = {r[1], r[2], r[3]};
        o.imu.accel = {r[4], r[5], r[6]};
        out.push_back(o);
      }
    }
    const earth::LocalFrame frame(m.origin);
    TruthReader truth(m.resolve(*m.truth_file));
    TruthRecord tr;
    while (truth.next(tr)) {
      OutMessage o;
      o.topic = "/ground_truth/odom";
      o.kind = ros::MessageKind::kOdometry;
      o.pose.stamp = stamp_ns(ns_of(tr.t));
      o.receive_ns = o.pose.stamp.ns() + kReceiveDelay;
      o.pose.frame_id = "map";
      o.pose.child_frame_id = "base_link";
      const Vec3 p_enu = kEnuToNed * frame.ned_from_geodetic(tr.lla);
      const Mat3 C_flu_enu = kEnuToNed * dcm_from_euler(tr.rpy) * kFrdToFlu;
      o.pose.position = {p_enu.x(), p_enu.y(), p_enu.z()};
      o.pose.orientation = xyzw(Quat(C_flu_enu));
      const Vec3 v_flu = C_flu_enu.transpose() * (kEnuToNed * tr.v_ned);
      o.pose.linear = {v_flu.x(), v_flu.y(), v_flu.z()};
      o.pose.has_twist = true;
      out.push_back(o);
    }
    for (const auto& r : rows(m.resolve(*m.odometer_file), 2)) {
      OutMessage o;
      o.topic = "/odom";
      o.kind = ros::MessageKind::kOdometry;
      o.pose.stamp = stamp_ns(ns_of(r[0]));
      o.receive_ns = o.pose.stamp.ns() + kReceiveDelay;
      o.pose.frame_id = "odom";
      o.pose.child_frame_id = "base_link";
      o.pose.linear = {r[1], 0.0, 0.0};
      o.pose.has_twist = true;
      out.push_back(o);
    }
    // In receive-time order, ties in the order made. (No std::stable_sort: its buffer comes
    // from the nothrow operator new, which the allocation-counting replacement of
    // test_io_imu_file.cpp does not replace, and ASan reports the mismatched delete.)
    std::vector<std::size_t> order(out.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return out[a].receive_ns != out[b].receive_ns ? out[a].receive_ns < out[b].receive_ns : a < b;
    });
    std::vector<OutMessage> sorted;
    sorted.reserve(out.size());
    for (std::size_t k : order) sorted.push_back(std::move(out[k]));
    out = std::move(sorted);
    OutMessage tf;
    tf.topic = "/tf_static";
    tf.kind = ros::MessageKind::kTf;
    tf.receive_ns = out.front().receive_ns;
    for (const Topic& t : topics) {
      ros::Transform x;
      x.stamp = stamp_ns(tf.receive_ns);
      x.parent = "base_link";
      x.child = t.frame;
      const Vec3 p = kFrdToFlu * m.find(t.module)->p_inV;
      x.translation = {p.x(), p.y(), p.z()};
      tf.tf.push_back(x);
    }
    out.insert(out.begin(), tf);
    return out;
  }

  static ros::ImportOptions options(bool named = true) {
    ros::ImportOptions o;
    if (named)
      for (const Topic& t : kTopics) o.topics.push_back({t.module, t.topic});
    o.truth_topic = "/ground_truth/odom";
    o.odometry_topic = "/odom";
    o.origin = manifest_->origin;
    return o;
  }

  /// Imports `recording` and checks every file against the simulated one.
  static fs::path import_and_compare(const fs::path& recording, const std::string& name) {
    const fs::path out = scratch(name + "_out");
    compare(recording, name, out);
    return out;
  }
  static void compare(const fs::path& recording, const std::string& name, const fs::path& out) {
    const ros::ImportResult r = import_dataset(recording, out, options());
    EXPECT_EQ(r.imu.size(), 3u);
    const Manifest& m = *manifest_;
    for (const Topic& t : kTopics) {
      SCOPED_TRACE(name + " " + t.module);
      const auto a = rows(m.resolve(m.find(t.module)->file), 7);
      const auto b = rows(out / (t.module + "_imu.bin"), 7);
      ASSERT_EQ(a.size(), b.size());
      double dt = 0.0;
      for (std::size_t k = 0; k < a.size(); ++k) {
        dt = std::max(dt, std::abs(a[k][0] - b[k][0]));
        for (int c = 1; c < 7; ++c) ASSERT_EQ(std::memcmp(&a[k][c], &b[k][c], 8), 0) << "row " << k << " col " << c;
      }
      EXPECT_LE(dt, 1e-9);
    }
    {
      const auto a = rows(m.resolve(*m.odometer_file), 2), b = rows(out / "odo.bin", 2);
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_LE(std::abs(a[k][0] - b[k][0]), 1e-9);
        EXPECT_EQ(a[k][1], b[k][1]);
      }
    }
    {
      const TruthData a = read_truth(m.resolve(*m.truth_file)), b = read_truth(out / "GINS.bin");
      ASSERT_EQ(a.records.size(), b.records.size());
      double dpos = 0, dvel = 0, datt = 0, dtime = 0;
      for (std::size_t k = 0; k < a.records.size(); ++k) {
        const auto &x = a.records[k], &y = b.records[k];
        dtime = std::max(dtime, std::abs(x.t - y.t));
        dpos = std::max({dpos, std::abs(x.lla.lat - y.lla.lat) * 6.4e6, std::abs(x.lla.lon - y.lla.lon) * 6.4e6,
                         std::abs(x.lla.h - y.lla.h)});
        dvel = std::max(dvel, (x.v_ned - y.v_ned).norm());
        for (int i = 0; i < 3; ++i) datt = std::max(datt, std::abs(wrap_pi(x.rpy[i] - y.rpy[i])));
      }
      EXPECT_LE(dtime, 1e-9);
      EXPECT_LE(dpos, 1e-6);   // [m]: the local ENU round trip
      EXPECT_LE(dvel, 1e-12);  // [m/s]
      EXPECT_LE(datt, 1e-12);  // [rad]
    }
    // The drafted manifest: modules named as asked, positions from /tf_static, kinds by name.
    const Manifest d = load_manifest(out / "manifest.yaml", {});
    EXPECT_EQ(d.modules.size(), 3u);
    for (const Topic& t : kTopics) {
      const ModuleSpec* s = d.find(t.module);
      ASSERT_NE(s, nullptr) << t.module;
      EXPECT_LE((s->p_inV - m.find(t.module)->p_inV).norm(), 1e-12) << t.module;
      EXPECT_EQ(s->kind, t.module == "body-C1" ? ModuleKind::kBody : ModuleKind::kWheel);
      EXPECT_EQ(s->rate_hz, 200.0);
    }
    EXPECT_TRUE(d.truth_file && d.odometer_file);
  }

  /// Triple INS on a manifest, in memory: every vehicle record.
  static std::vector<TrajectoryRecord> navigate(const Manifest& m) {
    RunRequest r;
    r.manifest = m;
    r.modules = configuration_modules(m, "triple", {});
    r.nav.earth_rotation = m.earth_rotation;
    r.nav.module_records = false;
    r.progress = false;
    std::vector<TrajectoryRecord> recs;
    r.on_record = [&](const TrajectoryRecord& rec) { recs.push_back(rec); };
    run_navigation(r);
    return recs;
  }

  static std::string bytes(const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

  static fs::path* dataset_;
  static Manifest* manifest_;
  static std::vector<OutMessage>* msgs_;
};
fs::path* RosImport::dataset_ = nullptr;
Manifest* RosImport::manifest_ = nullptr;
std::vector<OutMessage>* RosImport::msgs_ = nullptr;

// The done-when of the import: the three formats give the simulated files, the same bytes
// from each, and a run on the imported dataset gives the run on the original.
TEST_F(RosImport, ThreeFormatsImportToTheSimulatedFilesAndRunAlike) {
  const fs::path dir = scratch("bags");
  fs::create_directories(dir);
  write_ros2_db3(dir / "sim.db3", *msgs_);
  write_ros2_mcap(dir / "sim.mcap", *msgs_);
  const fs::path b = import_and_compare(dir / "sim.db3", "db3");
  const fs::path c = import_and_compare(dir / "sim.mcap", "mcap");
#if WHEELINS_HAVE_ROS1
  write_ros1_bag(dir / "sim.bag", *msgs_, "lz4");
  const fs::path a = import_and_compare(dir / "sim.bag", "ros1");
#else
  const fs::path a = b;  // a build without ROS 1 (WHEELINS_ROS1=OFF): two formats
#endif
  for (const char* f : {"left-C1_imu.bin", "right-C1_imu.bin", "body-C1_imu.bin", "GINS.bin", "odo.bin"}) {
    EXPECT_EQ(bytes(a / f), bytes(b / f)) << f;
    EXPECT_EQ(bytes(a / f), bytes(c / f)) << f;
  }

  // The original manifest with the imported files: the same trajectory.
  Manifest imported = *manifest_;
  for (ModuleSpec& s : imported.modules)
    if (fs::exists(a / (s.name + "_imu.bin"))) s.file = a / (s.name + "_imu.bin");
  imported.truth_file = a / "GINS.bin";
  imported.odometer_file = a / "odo.bin";
  const auto x = navigate(*manifest_), y = navigate(imported);
  ASSERT_EQ(x.size(), y.size());
  ASSERT_GT(x.size(), 1000u);
  // The simulated times (start + k / rate) are the doubles nearest to their nanosecond
  // stamps, so they come back bit-exact, and so does the whole run.
  bool same_times = true;
  for (const Topic& t : kTopics) {
    const auto p = rows(manifest_->resolve(manifest_->find(t.module)->file), 7), q = rows(a / (t.module + "_imu.bin"), 7);
    for (std::size_t k = 0; k < p.size(); ++k) same_times = same_times && p[k][0] == q[k][0];
  }
  EXPECT_TRUE(same_times);
  double dp = 0, dh = 0, dt = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    dt = std::max(dt, std::abs(x[k].t - y[k].t));
    dp = std::max(dp, (x[k].p_inN - y[k].p_inN).norm());
    dh = std::max(dh, std::abs(wrap_pi(x[k].rpy.z() - y[k].rpy.z())));
  }
  RecordProperty("max_position_difference_m", std::to_string(dp));
  std::printf("run on the imported dataset vs the original: max |dt| %.3g s, |dp| %.3g m, |dheading| %.3g rad\n",
              dt, dp, dh);
  EXPECT_LE(dt, same_times ? 0.0 : 1e-9);
  EXPECT_LE(dp, same_times ? 0.0 : 1e-6);
  EXPECT_LE(dh, same_times ? 0.0 : 1e-9);
  for (const auto& p : {a, b, c, dir}) fs::remove_all(p);
}

// The other MCAP shapes (lz4, uncompressed chunks, no chunks), big-endian CDR, an ROS 2 bag
// directory, and the default module names (after the topics) with receive times.
TEST_F(RosImport, McapVariantsBigEndianCdrBagDirectoryAndTopicNames) {
  const fs::path dir = scratch("variants");
  fs::create_directories(dir / "bag2");
  write_ros2_mcap(dir / "lz4.mcap", *msgs_, {"lz4", 300, true, true});
  write_ros2_mcap(dir / "plain.mcap", *msgs_, {"", 700, false, true});
  write_ros2_mcap(dir / "nochunk.mcap", *msgs_, {"", 0, false, true});
  write_ros2_db3(dir / "bag2" / "bag2_0.db3", *msgs_, true);
  std::ofstream(dir / "bag2" / "metadata.yaml") << "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n";
  for (const fs::path& rec : {dir / "lz4.mcap", dir / "plain.mcap", dir / "nochunk.mcap", dir / "bag2"})
    fs::remove_all(import_and_compare(rec, rec.stem().string()));

  ros::ImportOptions o = options(false);
  o.receive_time = true;
  const fs::path out = scratch("names");
  const ros::ImportResult r = import_dataset(dir / "lz4.mcap", out, o);
  ASSERT_EQ(r.imu.size(), 3u);
  const Manifest d = load_manifest(out / "manifest.yaml", {});
  for (const char* name : {"left_wheel_imu", "right_wheel_imu", "body_imu"}) EXPECT_NE(d.find(name), nullptr) << name;
  EXPECT_EQ(d.find("body_imu")->kind, ModuleKind::kBody);
  const auto a = rows(manifest_->resolve(manifest_->find("left-C1")->file), 7);
  const auto b = rows(out / "left_wheel_imu_imu.bin", 7);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(b[k][0] - a[k][0], 1e-3, 1e-9);
  fs::remove_all(out);
  fs::remove_all(dir);
}

// The truth as geometry_msgs/PoseStamped in NED/FRD (no twist: velocities by central
// differences), and /tf_static positions through a chain of static frames.
TEST_F(RosImport, PoseStampedTruthInNedAndChainedStaticFrames) {
  std::vector<OutMessage> msgs;
  const earth::LocalFrame frame(manifest_->origin);
  for (const OutMessage& m : *msgs_) {
    if (m.topic == "/tf_static") {
      OutMessage tf = m;
      // body_imu hangs off a mount frame: base_link -> mount (turned 90 deg about z) -> body_imu.
      const Quat q(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));
      const Vec3 mount(0.1, 0.0, 0.05);
      for (auto& x : tf.tf)
        if (x.child == "body_imu") {
          const Vec3 p = Vec3(x.translation[0], x.translation[1], x.translation[2]);
          const Vec3 local = q.inverse() * (p - mount);
          x.parent = "mount";
          x.translation = {local.x(), local.y(), local.z()};
          ros::Transform y;
          y.parent = "base_link";
          y.child = "mount";
          y.translation = {mount.x(), mount.y(), mount.z()};
          y.rotation = xyzw(q);
          tf.tf.push_back(y);
          break;
        }
      msgs.push_back(tf);
    } else if (m.topic == "/ground_truth/odom") {
      OutMessage p = m;
      p.kind = ros::MessageKind::kPoseStamped;
      p.topic = "/ground_truth/pose";
      p.pose.has_twist = false;
      msgs.push_back(p);
    } else {
      msgs.push_back(m);
    }
  }
  // Rewrite the truth poses in NED/FRD from the original truth.
  TruthReader truth(manifest_->resolve(*manifest_->truth_file));
  TruthRecord tr;
  std::vector<TruthRecord> original;
  for (OutMessage& m : msgs) {
    if (m.topic != "/ground_truth/pose") continue;
    ASSERT_TRUE(truth.next(tr));
    original.push_back(tr);
    const Vec3 p = frame.ned_from_geodetic(tr.lla);
    m.pose.position = {p.x(), p.y(), p.z()};
    m.pose.orientation = xyzw(Quat(dcm_from_euler(tr.rpy)));
  }
  const fs::path dir = scratch("pose");
  fs::create_directories(dir);
  write_ros2_db3(dir / "pose.db3", msgs);
  ros::ImportOptions o = options();
  o.truth_topic = "/ground_truth/pose";
  o.convention = ros::PoseConvention::kNedFrd;
  const fs::path out = dir / "out";
  const ros::ImportResult r = import_dataset(dir / "pose.db3", out, o);
  ASSERT_TRUE(r.truth);
  const TruthData b = read_truth(out / "GINS.bin");
  ASSERT_EQ(b.records.size(), original.size());
  double dpos = 0, datt = 0, dvel = 0;
  for (std::size_t k = 1; k + 1 < original.size(); ++k) {
    const auto &x = original[k], &y = b.records[k];
    dpos = std::max(dpos, (frame.ned_from_geodetic(x.lla) - frame.ned_from_geodetic(y.lla)).norm());
    for (int i = 0; i < 3; ++i) datt = std::max(datt, std::abs(wrap_pi(x.rpy[i] - y.rpy[i])));
    dvel = std::max(dvel, (x.v_ned - y.v_ned).norm());
  }
  EXPECT_LE(dpos, 1e-6);
  EXPECT_LE(datt, 1e-12);
  EXPECT_LE(dvel, 1e-5);  // central differences of 200 Hz positions vs the exact velocity [m/s] (1.1e-6)
  EXPECT_GT(dvel, 0.0);
  const Manifest d = load_manifest(out / "manifest.yaml", {});
  EXPECT_LE((d.find("body-C1")->p_inV - manifest_->find("body-C1")->p_inV).norm(), 1e-12);
  fs::remove_all(dir);
}

// A bag as ROS drivers name things (/imu0, /imu1, /imu2; the Body-IMU first), imported
// without --truth: the draft tells the modules by whether they spin, finds the static period
// where every module rests, takes the positions /tf_static states as measured (and the track
// from them), lists what is still unknown and points at the bag's Odometry topics; the
// drafted manifest navigates as it is.
TEST_F(RosImport, GenericTopicNamesDraftAManifestThatNavigates) {
  const fs::path dir = scratch("generic");
  simulate_small(dir / "sim", 5.0, 30.0);
  const Manifest original = load_manifest(dir / "sim" / "manifest.yaml", {});
  const std::vector<Topic> topics = {{"body-C1", "/imu0", "imu0"}, {"left-C1", "/imu1", "imu1"}, {"right-C1", "/imu2", "imu2"}};
#if WHEELINS_HAVE_ROS1
  const fs::path recording = dir / "generic.bag";
  write_ros1_bag(recording, messages(original, topics));
#else
  const fs::path recording = dir / "generic.mcap";  // no ROS 1 writer in this build
  write_ros2_mcap(recording, messages(original, topics));
#endif

  RosDatasetOptions o;
  o.vehicle_type = "robot";  // the simulated vehicle's typical values where the data cannot tell
  const RosDatasetResult r = import_ros_dataset(recording, dir / "ds", o);
  std::string todo;
  for (const auto& t : r.draft.todo) todo += t + "\n";
  SCOPED_TRACE(survey::survey_report(r.survey) + todo);
  const Manifest d = load_manifest(dir / "ds" / "manifest.yaml", {});
  ASSERT_EQ(d.modules.size(), 3u);
  EXPECT_EQ(d.find("imu0")->kind, ModuleKind::kBody);
  EXPECT_EQ(d.find("imu1")->kind, ModuleKind::kWheel);
  EXPECT_EQ(d.find("imu2")->kind, ModuleKind::kWheel);
  // Positions and the track as /tf_static states them.
  for (const Topic& t : topics)
    EXPECT_LE((d.find(t.frame)->p_inV - original.find(t.module)->p_inV).norm(), 1e-12) << t.frame;
  EXPECT_NEAR(d.track_width, original.find("right-C1")->p_inV.y() - original.find("left-C1")->p_inV.y(), 1e-4);
  // The static period: the vehicle rests all through it, and it is most of the rest there is.
  const TruthData truth = read_truth(original.resolve(*original.truth_file));
  double fastest = 0.0, moving_from = 0.0;
  for (const TruthRecord& x : truth.records) {
    if (x.t >= d.static_start && x.t <= d.static_end) fastest = std::max(fastest, x.v_ned.norm());
    if (moving_from == 0.0 && x.v_ned.norm() > 0.02) moving_from = x.t;
  }
  EXPECT_LT(fastest, 0.01);
  EXPECT_GE(d.static_start, truth.records.front().t);
  EXPECT_GT(d.static_end - d.static_start, 3.0);
  EXPECT_LE(d.static_end, moving_from);
  // The TODO list: what is still unknown, not what /tf_static said; the Odometry topics offered.
  EXPECT_EQ(todo.find("position_v_m"), std::string::npos);
  EXPECT_EQ(todo.find("track_m"), std::string::npos);
  EXPECT_NE(todo.find("wheel_radius_m"), std::string::npos);
#if WHEELINS_HAVE_ROS1
  EXPECT_NE(todo.find("/ground_truth/odom (nav_msgs/Odometry)"), std::string::npos);
#else
  EXPECT_NE(todo.find("/ground_truth/odom (nav_msgs/msg/Odometry)"), std::string::npos);  // ROS 2's type name
#endif
  EXPECT_NE(todo.find("--truth TOPIC"), std::string::npos);

  // It navigates: the distances from the start agree with the truth's (no heading is known,
  // so the track is compared without its turn about the vertical).
  const auto recs = navigate(d);
  ASSERT_GT(recs.size(), 1000u);
  const earth::LocalFrame frame(truth.records.front().lla);
  const Vec3 p0 = recs.front().p_inN;
  const Vec3 q0 = frame.ned_from_geodetic(truth.records.front().lla);
  double worst = 0.0, farthest = 0.0;
  std::size_t k = 0;
  for (const TruthRecord& x : truth.records) {
    while (k + 1 < recs.size() && recs[k].t < x.t) ++k;
    if (std::abs(recs[k].t - x.t) > 0.01) continue;
    const double want = (frame.ned_from_geodetic(x.lla) - q0).head<2>().norm();
    const double got = (recs[k].p_inN - p0).head<2>().norm();
    worst = std::max(worst, std::abs(got - want));
    farthest = std::max(farthest, want);
  }
  EXPECT_GT(farthest, 5.0);
  EXPECT_LT(worst, 0.02 * farthest + 0.1) << "over " << farthest << " m";
  fs::remove_all(dir);
}

// --- bad input -----------------------------------------------------------------------

/// Twenty IMU messages on /imu and five Odometry messages on /odom.
std::vector<OutMessage> small_bag() {
  std::vector<OutMessage> v;
  for (int k = 0; k < 20; ++k) {
    OutMessage o;
    o.topic = "/imu";
    o.imu.stamp = stamp_ns(100000000000 + 5000000LL * k);
    o.receive_ns = o.imu.stamp.ns() + 1000;
    o.imu.frame_id = "imu";
    o.imu.gyro = {0.01 * k, 0.0, 0.0};
    o.imu.accel = {0.0, 0.0, -9.8};
    v.push_back(o);
    if (k % 4 == 0) {
      OutMessage d;
      d.topic = "/odom";
      d.kind = ros::MessageKind::kOdometry;
      d.pose.stamp = o.imu.stamp;
      d.receive_ns = o.receive_ns;
      d.pose.has_twist = true;
      v.push_back(d);
    }
  }
  return v;
}

std::string import_error(const fs::path& rec, const ros::ImportOptions& o = {}) {
  const fs::path out = scratch("bad_out");
  std::string what;
  try {
    ros::import_recording(rec, out, o);
  } catch (const InputError& e) {
    what = e.what();
  }
  // All or nothing: a failed import leaves no data files.
  std::error_code ec;
  if (fs::exists(out))
    for (const auto& e : fs::directory_iterator(out, ec)) ADD_FAILURE() << "left behind: " << e.path();
  fs::remove_all(out, ec);
  return what;
}

using Writer = void (*)(const fs::path&, const std::vector<OutMessage>&);
void db3(const fs::path& f, const std::vector<OutMessage>& m) { write_ros2_db3(f, m); }
void mcap(const fs::path& f, const std::vector<OutMessage>& m) { write_ros2_mcap(f, m); }
#if WHEELINS_HAVE_ROS1
void ros1(const fs::path& f, const std::vector<OutMessage>& m) { write_ros1_bag(f, m); }
const std::vector<std::pair<const char*, Writer>> kFormats = {{"bag", ros1}, {"db3", db3}, {"mcap", mcap}};
#else
const std::vector<std::pair<const char*, Writer>> kFormats = {{"db3", db3}, {"mcap", mcap}};
#endif

TEST(RosImportErrors, BadMessagesNameFileTopicAndIndex) {
  const fs::path dir = scratch("badmsg");
  fs::create_directories(dir);
  for (const auto& [ext, write] : kFormats) {
    SCOPED_TRACE(ext);
    const fs::path f = dir / (std::string("x.") + ext);
    auto m = small_bag();
    // A zero header stamp is reported (with the option to use the receive time), not replaced.
    m[7].imu.stamp = {};  // m: /imu 0, /odom 0, /imu 1, 2, 3, 4, /odom 1, /imu 5
    ASSERT_EQ(m[7].topic, "/imu");
    write(f, m);
    std::string e = import_error(f);
    EXPECT_NE(e.find(f.string()), std::string::npos) << e;
    EXPECT_NE(e.find("topic '/imu', message 5 (0-based): header stamp is zero"), std::string::npos) << e;
    ros::ImportOptions rt;
    rt.receive_time = true;
    const fs::path out = scratch("rt_out");
    EXPECT_NO_THROW(ros::import_recording(f, out, rt));
    fs::remove_all(out);

    m = small_bag();
    m[7].imu.stamp = m[4].imu.stamp;  // /imu message 5 stamped as message 3
    write(f, m);
    e = import_error(f);
    EXPECT_NE(e.find("topic '/imu', message 5 (0-based): header stamp"), std::string::npos) << e;
    EXPECT_NE(e.find("goes back"), std::string::npos) << e;

    m = small_bag();
    m[7].imu.accel[1] = std::nan("");
    write(f, m);
    e = import_error(f);
    EXPECT_NE(e.find("topic '/imu', message 5 (0-based): linear_acceleration.y is NaN"), std::string::npos) << e;

    // Wrong types, unknown topics.
    write(f, small_bag());
    ros::ImportOptions o;
    o.topics = {{"imu", "/odom"}};
    e = import_error(f, o);
    EXPECT_NE(e.find("topic '/odom' has type"), std::string::npos) << e;
    EXPECT_NE(e.find("expected sensor_msgs/Imu"), std::string::npos) << e;
    o.topics = {{"imu", "/nothere"}};
    e = import_error(f, o);
    EXPECT_NE(e.find("--topic '/nothere': no such topic; the recording has: "), std::string::npos) << e;
    o.topics.clear();
    o.truth_topic = "/imu";
    e = import_error(f, o);
    EXPECT_NE(e.find("--truth topic '/imu' has type"), std::string::npos) << e;

    // Truncated: the last third cut off.
    const auto size = fs::file_size(f);
    fs::resize_file(f, size * 2 / 3);
    e = import_error(f);
    EXPECT_NE(e.find(f.string()), std::string::npos) << e;
    EXPECT_FALSE(e.empty());
  }
  fs::remove_all(dir);
}

TEST(RosImportErrors, CorruptRos2Payloads) {
  const fs::path dir = scratch("corrupt");
  fs::create_directories(dir);
  // A CDR payload cut short (written into the sqlite3 bag as it is).
  {
    auto m = small_bag();
    write_ros2_db3(dir / "x.db3", m);
    // Row 5 is /imu message 3 (rows: /imu 0, /odom 0, /imu 1, 2, 3): cut to 60 bytes.
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "x.db3").c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "UPDATE messages SET data = substr(data, 1, 60) WHERE id = 5", nullptr, nullptr,
                           nullptr),
              SQLITE_OK);
    sqlite3_close(db);
    const std::string e = import_error(dir / "x.db3");
    EXPECT_NE(e.find("topic '/imu' (sensor_msgs/msg/Imu), message 3 (0-based): CDR payload ends at byte 60"),
              std::string::npos)
        << e;
  }
  // MCAP: a flipped byte inside a compressed chunk (CRC or decompression fails), and a file
  // without its DataEnd / Footer.
  {
    write_ros2_mcap(dir / "x.mcap", small_bag(), {"", 10, true, true});
    std::string b;
    {
      std::ifstream in(dir / "x.mcap", std::ios::binary);
      std::stringstream ss;
      ss << in.rdbuf();
      b = ss.str();
    }
    b[b.size() / 2] ^= 0x40;
    std::ofstream(dir / "y.mcap", std::ios::binary) << b;
    std::string e = import_error(dir / "y.mcap");
    EXPECT_NE(e.find("Chunk CRC-32 does not match"), std::string::npos) << e;
    write_ros2_mcap(dir / "z.mcap", small_bag(), {"zstd", 10, true, false});
    e = import_error(dir / "z.mcap");
    EXPECT_NE(e.find("without a DataEnd or Footer record (truncated"), std::string::npos) << e;
  }
  // Not a recording at all.
  std::ofstream(dir / "notes.txt") << "hello";
  EXPECT_NE(import_error(dir / "notes.txt").find("not a ROS recording"), std::string::npos);
  fs::remove_all(dir);
}

#if WHEELINS_HAVE_ROS1
std::string file_bytes(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ROS 1 bags are read by a reader of our own that checks every length and offset, and the
// index against the chunks (the ROS bag library crashed, signal 11, on an index offset past
// its chunk). Each compression reads the messages the library wrote; corruptions are
// InputErrors naming the file and the byte of the record.
TEST(RosImportErrors, Ros1BagStructureIsCheckedNotTrusted) {
  const fs::path dir = scratch("ros1");
  fs::create_directories(dir);
  const auto msgs = small_bag();
  for (const char* compression : {"none", "lz4", "bz2"}) {
    SCOPED_TRACE(compression);
    write_ros1_bag(dir / "x.bag", msgs, compression);
    // The fuzzer's seeds (fuzz/corpus/ros1): bags of the first eight messages, under the
    // fuzzer's 4 KiB; WHEELINS_FUZZ_SEEDS=DIR writes them there.
    if (const char* seeds = std::getenv("WHEELINS_FUZZ_SEEDS")) {
      write_ros1_bag(dir / "seed.bag", std::vector<OutMessage>(msgs.begin(), msgs.begin() + 8), compression);
      std::ofstream(fs::path(seeds) / compression, std::ios::binary) << std::string(1, '\0')
                                                                      << file_bytes(dir / "seed.bag");
    }
    ros::Ros1BagReader r(dir / "x.bag");
    ros::Ros1Message m;
    std::size_t n = 0;
    while (r.next(m)) {
      ASSERT_LT(n, msgs.size());
      EXPECT_EQ(r.connections().at(m.conn).topic, msgs[n].topic);
      EXPECT_EQ(std::int64_t(m.sec) * 1000000000 + m.nsec, msgs[n].receive_ns);
      ros::Message d;
      ros::decode_ros1(msgs[n].kind, m.data, m.size, d);
      if (msgs[n].kind == ros::MessageKind::kImu) {
        EXPECT_EQ(d.imu.gyro, msgs[n].imu.gyro);
      }
      ++n;
    }
    EXPECT_EQ(n, msgs.size());
  }

  // (Six IMU messages and one Odometry: the mutants below are read twice per byte.)
  std::vector<OutMessage> few;
  for (const OutMessage& m : msgs)
    if (few.size() < 7 && (m.kind == ros::MessageKind::kImu || few.size() == 1)) few.push_back(m);
  write_ros1_bag(dir / "x.bag", few, "none");
  const std::string good = file_bytes(dir / "x.bag");
  auto error_of = [&](const std::string& bytes) {
    std::ofstream(dir / "y.bag", std::ios::binary) << bytes;
    return import_error(dir / "y.bag");
  };
  // The probe's crash: an index entry's offset past its chunk. The index data record's
  // header fields are written in name order (conn, count, op, ver); its data follow:
  // uint32 length, then (time uint64, offset uint32) entries.
  {
    std::string b = good;
    const auto op = b.find(std::string("op=\x04", 4));
    ASSERT_NE(op, std::string::npos);
    const std::string ver("ver=\x01\0\0\0", 8);
    const auto v = b.find(ver, op);
    ASSERT_NE(v, std::string::npos);
    const std::size_t entry = v + ver.size() + 4;
    const std::uint32_t past = 0x7FFFFF00u;
    std::memcpy(&b[entry + 8], &past, 4);
    const std::string e = error_of(b);
    EXPECT_NE(e.find((dir / "y.bag").string()), std::string::npos) << e;
    EXPECT_NE(e.find("Index data record, entry 0 (0-based): offset 2147483392 is not a message of connection"),
              std::string::npos)
        << e;
  }
  // A type recorded with another definition (its MD5 sum) is named, not decoded.
  {
    std::string b = good;
    const std::string md5 = "6a62c6daae103f4ff57a132d6f95cec2";
    for (auto k = b.find(md5); k != std::string::npos; k = b.find(md5, k + 1)) b[k] = 'f';
    const std::string e = error_of(b);
    EXPECT_NE(e.find("topic '/imu': message type 'sensor_msgs/Imu' (MD5 fa62c6daae103f4ff57a132d6f95cec2) is not "
                     "the sensor_msgs/Imu definition this build knows"),
              std::string::npos)
        << e;
  }
  // No index (a recorder stopped before it closed the file), and an index past the end.
  {
    std::string b = good;
    const std::string key("index_pos=", 10);
    const auto k = b.find(key);
    ASSERT_NE(k, std::string::npos);
    std::string zero = b;
    std::memset(&zero[k + key.size()], 0, 8);
    std::string e = error_of(zero);
    EXPECT_NE(e.find("the bag has no index"), std::string::npos) << e;
    std::memset(&b[k + key.size()], 0x7F, 8);
    e = error_of(b);
    EXPECT_NE(e.find("is outside the data"), std::string::npos) << e;
  }
  // Every byte of the file changed, one at a time, and the file cut at every length: the
  // reader reads or throws InputError, nothing else (under the sanitizers: no read out of
  // bounds). The import itself is left out: its rows are checked elsewhere.
  auto read_all = [&](const std::string& bytes) {
    try {
      ros::Ros1BagReader r("mutant", reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      ros::Ros1Message m;
      while (r.next(m)) {
        ros::Message d;
        for (auto kind : {ros::MessageKind::kImu, ros::MessageKind::kOdometry, ros::MessageKind::kTf}) {
          try {
            ros::decode_ros1(kind, m.data, m.size, d);
          } catch (const ros::CdrError&) {
          }
        }
      }
      return true;
    } catch (const InputError&) {
      return false;
    }
  };
  std::size_t rejected = 0;
  for (std::size_t i = 0; i < good.size(); ++i) {
    std::string b = good;
    b[i] = static_cast<char>(b[i] ^ 0xA5);
    rejected += read_all(b) ? 0 : 1;
    rejected += read_all(good.substr(0, i)) ? 0 : 1;
  }
  RecordProperty("mutants_rejected", std::to_string(rejected));
  EXPECT_GT(rejected, good.size());  // every cut, and the flips of the structure
  fs::remove_all(dir);
}
#endif  // WHEELINS_HAVE_ROS1

// The CDR decoder against hand-made payloads: alignment, both byte orders, bounds.
TEST(RosCdr, DecodesAlignedFieldsInBothByteOrdersAndRejectsShortData) {
  OutMessage m;
  m.imu.stamp = {12, 345};
  m.imu.gyro = {1.5, -2.25, 3e-9};
  m.imu.accel = {0.0, -0.0, 9.80665};
  // "abc" + NUL ends the string at byte 16 after the header: the orientation follows
  // without padding; "abcdefg" + NUL ends at 20: 4 bytes of padding to the next 8.
  for (const auto& [frame, pad] : {std::pair<std::string, std::size_t>{"abc", 0}, {"abcdefg", 4}})
  for (bool big : {false, true}) {
    m.imu.frame_id = frame;
    const auto p = cdr_payload(m, big);
    EXPECT_EQ(p.size(), 4u + 8 + 4 + frame.size() + 1 + pad + 32 + 72 + 24 + 72 + 24 + 72);
    const ros::ImuMessage d = ros::decode_imu(p.data(), p.size());
    EXPECT_EQ(d.stamp.sec, 12);
    EXPECT_EQ(d.stamp.nsec, 345u);
    EXPECT_EQ(d.frame_id, frame);
    EXPECT_EQ(d.gyro, m.imu.gyro);
    EXPECT_EQ(d.accel, m.imu.accel);
    for (std::size_t cut : {std::size_t(0), std::size_t(3), std::size_t(10), p.size() - 1})
      EXPECT_THROW(ros::decode_imu(p.data(), cut), ros::CdrError) << cut;
  }
  std::vector<std::uint8_t> bad = {0x00, 0x06, 0, 0, 0, 0, 0, 0};
  EXPECT_THROW(ros::decode_imu(bad.data(), bad.size()), ros::CdrError);
  EXPECT_EQ(ros::crc32(reinterpret_cast<const std::uint8_t*>("123456789"), 9), 0xCBF43926u);
}

}  // namespace

namespace {
// The command: a bag in, the dataset and the list of what is still to fill in out; a
// bad one: exit 2 and the error naming file, topic and message.
TEST(RosImportCli, ImportsOrFailsWithExitCodeAndMessage) {
  const fs::path dir = scratch("cli");
  fs::create_directories(dir);
  auto m = small_bag();
  write_ros2_mcap(dir / "ok.mcap", m);
  m[7].imu.gyro[2] = INFINITY;
#if WHEELINS_HAVE_ROS1
  const fs::path bad = dir / "bad.bag";
  write_ros1_bag(bad, m);
#else
  const fs::path bad = dir / "bad.mcap";
  write_ros2_mcap(bad, m);
#endif
  auto run = [&](const std::string& args, std::string& out) {
    const std::string cmd = std::string("'") + WHEELINS_BINARY + "' import " + args + " >'" +
                            (dir / "stdout").string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    std::ifstream in(dir / "stdout");
    std::stringstream ss;
    ss << in.rdbuf();
    out = ss.str();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  std::string out;
  EXPECT_EQ(run("'" + (dir / "ok.mcap").string() + "' --out '" + (dir / "ds").string() + "' --odometry /odom", out), 0)
      << out;
  EXPECT_NE(out.find("ROS 2 MCAP"), std::string::npos) << out;
  EXPECT_NE(out.find("still to fill in"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir / "ds" / "imu_imu.bin") && fs::exists(dir / "ds" / "odo.bin") &&
              fs::exists(dir / "ds" / "manifest.yaml"));
  EXPECT_NO_THROW(load_manifest(dir / "ds" / "manifest.yaml", {}));
  EXPECT_EQ(run("'" + bad.string() + "' --out '" + (dir / "ds2").string() + "'", out), 2) << out;
  EXPECT_NE(out.find("error: '" + bad.string() +
                     "': topic '/imu', message 5 (0-based): angular_velocity.z is infinite"),
            std::string::npos)
      << out;
  EXPECT_EQ(run("'" + (dir / "ok.mcap").string() + "' --out '" + (dir / "ds").string() + "'", out), 2) << out;
  EXPECT_NE(out.find("is not empty (use --force"), std::string::npos) << out;
  fs::remove_all(dir);
}

// The program reads every ROS recording with readers of its own (ROS 1 bags, ROS 2 bags,
// MCAP), so it links no ROS, boost or Python library, in the default build as in one without
// Debian's ROS packages (cmake -DWHEELINS_ROS1=OFF, which leaves out only the tests' ROS 1
// writer): a cluster node or a machine without ROS runs it as it is.
TEST(RosFreeBuild, TheProgramLinksNothingOfRos) {
  const fs::path dir = scratch("rosfree");
  fs::create_directories(dir);
  const std::string cmd = std::string("ldd '") + WHEELINS_BINARY + "' >'" + (dir / "ldd").string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(dir / "ldd");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string libs = ss.str();
  EXPECT_NE(libs.find("libyaml-cpp"), std::string::npos) << libs;  // ldd did list the libraries
  for (const char* banned : {"libros", "librosbag", "libboost", "libpython", "libconsole_bridge"})
    EXPECT_EQ(libs.find(banned), std::string::npos) << banned << " linked:\n" << libs;
  fs::remove_all(dir);
}
}  // namespace
