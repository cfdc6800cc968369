// `wheelins import RECORDING --out DIR`: ROS bags (ROS 1 .bag, ROS 2 .db3 / .mcap) into
// the Wheel-INS layout and a drafted manifest (docs/ros-import.md).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli.hpp"
#include "wheelins/util/progress.hpp"
#include "wheelins/io/ros/import.hpp"
#include "wheelins/nav/types.hpp"

namespace {
using namespace wheelins;

struct Options {
  std::string recording, out, odometry, truth, origin, convention = "enu", base_frame = "base_link";
  std::vector<std::string> topics;
  bool receive_time = false, force = false, quiet = false;
};

earth::Geodetic parse_origin(const std::string& text) {
  double v[3];
  char tail;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 ||
      !(std::abs(v[0]) <= 90.0) || !(std::abs(v[1]) <= 180.0) || !std::isfinite(v[2]))
    throw InputError("--origin '" + text + "': expected LAT_DEG,LON_DEG,H_M (latitude within +-90, "
                     "longitude within +-180)");
  return {v[0] * kDeg, v[1] * kDeg, v[2]};
}

int run(const Options& o) {
  ros::ImportOptions opt;
  for (const auto& t : o.topics) {
    const auto eq = t.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == t.size())
      throw InputError("--topic '" + t + "': expected MODULE=TOPIC, e.g. left-C1=/left_wheel/imu");
    opt.topics.push_back({t.substr(0, eq), t.substr(eq + 1)});
  }
  opt.odometry_topic = o.odometry;
  opt.truth_topic = o.truth;
  opt.receive_time = o.receive_time;
  if (!o.origin.empty()) opt.origin = parse_origin(o.origin);
  if (o.convention == "enu") opt.convention = ros::PoseConvention::kEnuFlu;
  else if (o.convention == "ned") opt.convention = ros::PoseConvention::kNedFrd;
  else throw InputError("--truth-frame '" + o.convention + "': expected enu (REP 103) or ned");
  opt.base_frame = o.base_frame;
  opt.force = o.force;
  opt.warn = stderr_sink();
  std::unique_ptr<Progress> bar;  // on a terminal: messages read of those to read
  opt.progress = [&](std::uint64_t done, std::uint64_t total) {
    if (!bar) bar = std::make_unique<Progress>("importing", total, !o.quiet);
    bar->update(done);
  };

  const ros::ImportResult r = ros::import_recording(o.recording, o.out, opt);
  if (bar) bar->finish();
  std::cout << "imported " << o.recording << " (" << r.format << ")\n";
  for (const auto& t : r.imu)
    std::printf("  %-28s -> %s: %llu samples, %.3f .. %.3f s%s\n", t.topic.c_str(), t.file.string().c_str(),
                static_cast<unsigned long long>(t.messages), t.t_first, t.t_last,
                t.frame_id.empty() ? "" : (", frame " + t.frame_id).c_str());
  for (const auto* t : {&r.truth, &r.odometer})
    if (*t)
      std::printf("  %-28s -> %s: %llu records, %.3f .. %.3f s\n", (*t)->topic.c_str(),
                  (*t)->file.string().c_str(), static_cast<unsigned long long>((*t)->messages),
                  (*t)->t_first, (*t)->t_last);
  std::cout << "wrote " << r.manifest_file.string() << "\n";
  for (const auto& f : r.facts) std::cout << "  " << f << "\n";
  std::cout << "still to fill in (marked TODO in the file):\n";
  for (const auto& t : r.draft.todo) std::cout << "  - " << t << "\n";
  return 0;
}

const bool registered = cli::register_command(
    16, "import", "Import a ROS recording (ROS 1 .bag, ROS 2 .db3/.mcap) as a dataset with a drafted manifest",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("RECORDING", o->recording, "ROS 1 .bag, ROS 2 .db3 or .mcap file, or a ROS 2 bag directory")
          ->required();
      sub.add_option("--out,-o", o->out, "Output dataset directory (empty or new)")->required();
      sub.add_option("--topic", o->topics,
                     "MODULE=TOPIC: import this sensor_msgs/Imu topic as module MODULE (repeatable; "
                     "default: every Imu topic, named after it)");
      sub.add_option("--odometry", o->odometry, "nav_msgs/Odometry topic whose twist.linear.x becomes odo.bin");
      sub.add_option("--truth", o->truth,
                     "nav_msgs/Odometry or geometry_msgs/PoseStamped topic that becomes the truth GINS.bin");
      sub.add_option("--origin", o->origin,
                     "LAT_DEG,LON_DEG,H_M of the truth frame's origin (default: a 0,0,0 placeholder)");
      sub.add_option("--truth-frame", o->convention,
                     "enu: world ENU, body FLU (REP 103); ned: world NED, body FRD")
          ->capture_default_str();
      sub.add_option("--base-frame", o->base_frame, "vehicle frame of /tf_static (module positions)")
          ->capture_default_str();
      sub.add_flag("--receive-time", o->receive_time,
                   "time = the recorder's receive time instead of the message header stamp");
      sub.add_flag("--quiet,-q", o->quiet, "no progress line");
      sub.add_flag("--force,-f", o->force, "write into a non-empty directory, replacing files of the same names");
      return [o]() { return run(*o); };
    });
}  // namespace
