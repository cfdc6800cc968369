// `wheelins import RECORDING --out DIR`: ROS bags (ROS 1 .bag, ROS 2 .db3 / .mcap) into
// the Wheel-INS layout and a drafted manifest (docs/ros-import.md); or vendors' CSV/text
// tables (`--preset`, `--columns`) into IMU files and a manifest drafted from what the data
// say (docs/csv-import.md, docs/real-data.md).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli.hpp"
#include "wheelins/util/progress.hpp"
#include "wheelins/io/ros/import.hpp"
#include "wheelins/run/ros_dataset.hpp"
#include "wheelins/run/table_dataset.hpp"
#include "wheelins/nav/types.hpp"

namespace {
using namespace wheelins;

struct Options {
  std::vector<std::string> recordings;
  std::string out, odometry, truth, origin, convention = "enu", base_frame = "base_link";
  std::vector<std::string> topics;
  std::string preset, columns, vehicle_type, vehicle;
  double max_bad_fraction = 0.01;
  bool receive_time = false, force = false, quiet = false;
};

int run_tables(const Options& o) {
  if (!o.topics.empty() || !o.odometry.empty() || o.receive_time)
    throw InputError("--topic, --odometry and --receive-time are for ROS recordings; tables are imported by --preset/--columns");
  TableDatasetOptions t;
  for (const auto& r : o.recordings) t.inputs.push_back(r);
  t.out_dir = o.out;
  t.preset = o.preset;
  t.columns = o.columns;
  t.max_bad_fraction = o.max_bad_fraction;
  if (!o.truth.empty()) t.truth = o.truth;
  t.vehicle_type = o.vehicle_type;
  if (!o.vehicle.empty()) t.vehicle = o.vehicle;
  t.overwrite = o.force;
  t.progress = !o.quiet;
  t.warn = stderr_sink();
  const TableDatasetResult r = import_table_dataset(t);
  std::cout << table_import_report(r.tables);
  for (const auto& s : r.skipped) std::cout << "  skipped " << s << "\n";
  if (!r.truth_file.empty())
    std::printf("  reference %s: %zu records\n", r.truth_file.string().c_str(), r.truth_records);
  std::cout << "what the data say (every module's notes are comments in the manifest):\n" << survey::survey_report(r.survey);
  for (const auto& f : r.draft.facts) std::cout << "  " << f << "\n";
  std::cout << "wrote " << r.manifest_file.string() << "\n";
  if (!r.draft.todo.empty()) {
    std::cout << "still to fill in (marked TODO in the file):\n";
    for (const auto& d : r.draft.todo) std::cout << "  - " << d << "\n";
  }
  return 0;
}

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
  if (!o.preset.empty() || !o.columns.empty() || (!o.recordings.empty() && looks_like_tables(o.recordings.front())))
    return run_tables(o);
  if (o.recordings.size() != 1)
    throw InputError("a ROS recording is imported one at a time (" + std::to_string(o.recordings.size()) +
                     " given); several tables need --preset or --columns");
  const std::string& recording = o.recordings.front();
  RosDatasetOptions ro;
  ro.vehicle_type = o.vehicle_type;
  if (!o.vehicle.empty()) ro.vehicle = o.vehicle;
  ros::ImportOptions& opt = ro.import;
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

  const RosDatasetResult d = import_ros_dataset(recording, o.out, ro);
  const ros::ImportResult& r = d.import;
  if (bar) bar->finish();
  std::cout << "imported " << recording << " (" << r.format << ")\n";
  for (const auto& t : r.imu)
    std::printf("  %-28s -> %s: %llu samples, %.3f .. %.3f s%s\n", t.topic.c_str(), t.file.string().c_str(),
                static_cast<unsigned long long>(t.messages), t.t_first, t.t_last,
                t.frame_id.empty() ? "" : (", frame " + t.frame_id).c_str());
  for (const auto* t : {&r.truth, &r.odometer})
    if (*t)
      std::printf("  %-28s -> %s: %llu records, %.3f .. %.3f s\n", (*t)->topic.c_str(),
                  (*t)->file.string().c_str(), static_cast<unsigned long long>((*t)->messages),
                  (*t)->t_first, (*t)->t_last);
  std::cout << "what the data say (every module's notes are comments in the manifest):\n" << survey::survey_report(d.survey);
  std::cout << "wrote " << d.manifest_file.string() << "\n";
  for (const auto& f : d.draft.facts)
    if (f.rfind("what the data say:", 0) != 0) std::cout << "  " << f << "\n";
  if (!d.draft.todo.empty()) {
    std::cout << "still to fill in (marked TODO in the file):\n";
    for (const auto& t : d.draft.todo) std::cout << "  - " << t << "\n";
  }
  return 0;
}

const bool registered = cli::register_command(
    16, "import",
    "Import a ROS recording (ROS 1 .bag, ROS 2 .db3/.mcap) or vendors' CSV tables as a dataset with a drafted manifest",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("RECORDING", o->recordings,
                     "ROS 1 .bag, ROS 2 .db3 or .mcap file, or a ROS 2 bag directory; or CSV/text tables "
                     "(files, or directories of *.csv / *.txt), one IMU each")
          ->required();
      sub.add_option("--preset", o->preset, "tables: the column map preset: xsens-dot | csv (docs/csv-import.md)");
      sub.add_option("--columns", o->columns, "tables: a column map (MAP.yaml or a string) refining the preset");
      sub.add_option("--max-bad-fraction", o->max_bad_fraction,
                     "tables: the largest fraction of a table's rows that may be left out as faults")
          ->capture_default_str();
      sub.add_option("--vehicle-type", o->vehicle_type,
                     "car | robot: the typical values written where the data cannot tell (default car)");
      sub.add_option("--vehicle", o->vehicle,
                     "a calibrated manifest of the same vehicle: its radii, mountings, lever arms, "
                     "positions and antenna are used for modules of the same name");
      sub.add_option("--out,-o", o->out, "Output dataset directory (empty or new)")->required();
      sub.add_option("--topic", o->topics,
                     "MODULE=TOPIC: import this sensor_msgs/Imu topic as module MODULE (repeatable; "
                     "default: every Imu topic, named after it)");
      sub.add_option("--odometry", o->odometry, "nav_msgs/Odometry topic whose twist.linear.x becomes odo.bin");
      sub.add_option("--truth", o->truth,
                     "ROS: nav_msgs/Odometry or geometry_msgs/PoseStamped topic that becomes the truth GINS.bin; "
                     "tables: a reference track file (GNSS CSV with time, lat, lon, height; TUM; Wheel-INS binary)");
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
