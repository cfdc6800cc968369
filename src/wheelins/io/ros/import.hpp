// `wheelins import`: a ROS recording (ROS 1 .bag, ROS 2 .db3 / .mcap / bag directory)
// into the Wheel-INS layout the readers take (docs/ros-import.md):
//
//   OUT/<module>_imu.bin   one per sensor_msgs/Imu topic: 7 float64 LE columns
//                          t [s], angular_velocity x y z [rad/s], linear_acceleration
//                          x y z [m/s^2]; t from the header stamp (or the receive time)
//   OUT/GINS.bin           (--truth TOPIC) 11 columns, docs/evaluation.md, from
//                          nav_msgs/Odometry or geometry_msgs/PoseStamped
//   OUT/odo.bin            (--odometry TOPIC) t, forward speed (twist.linear.x) of a
//                          nav_msgs/Odometry topic
//
// The manifest is drafted above this layer (run/ros_dataset.hpp: the modules surveyed as
// `wheelins manifest` surveys IMU files side by side); the import reports what it needs:
// the module positions /tf_static states and the pose topics it did not import.
//
// Every message is checked: a header stamp of zero, stamps that do not increase within
// a topic, and NaN or infinite values are InputErrors naming the file, the topic and the
// 0-based message index; so are a topic of the wrong type and a truncated recording.
// Nothing is left behind on an error (all files appear together at the end).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/nav/earth.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::ros {

struct TopicModule {
  std::string module;  ///< module name (file <module>_imu.bin)
  std::string topic;
};

/// How the truth topic's poses are expressed.
enum class PoseConvention {
  kEnuFlu,  ///< REP 103: world x east, y north, z up; body x forward, y left, z up
  kNedFrd,  ///< world x north, y east, z down; body x forward, y right, z down
};

struct ImportOptions {
  std::vector<TopicModule> topics;  ///< empty: every sensor_msgs/Imu topic, named after it
  std::string odometry_topic;       ///< nav_msgs/Odometry -> odo.bin; empty: none
  std::string truth_topic;          ///< Odometry or PoseStamped -> GINS.bin; empty: none
  bool receive_time = false;        ///< time = the recorder's receive time, not the header stamp
  /// Geodetic position of the truth frame's origin; none: 0 deg, 0 deg, 0 m (a placeholder,
  /// warned about and listed as a TODO: gravity and earth rate depend on it).
  std::optional<earth::Geodetic> origin;
  PoseConvention convention = PoseConvention::kEnuFlu;
  std::string base_frame = "base_link";  ///< the vehicle frame in /tf_static
  bool force = false;                    ///< write into a non-empty OUT, replacing our files
  WarningSink warn;
  /// Called every few thousand messages with (messages read, messages to read; 0 if unknown).
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

struct ImportedTopic {
  std::string module, topic, frame_id;
  std::filesystem::path file;
  std::uint64_t messages = 0;
  double t_first = 0.0, t_last = 0.0;
};

/// A module's position from /tf_static.
struct TfPosition {
  Vec3 p_inV = Vec3::Zero();  ///< [m] v-frame (x forward, y right, z down)
  std::string chain;          ///< "/tf_static: base_link -> left_wheel_imu"
};

struct ImportResult {
  std::string format;  ///< the recording's format
  std::vector<ImportedTopic> imu;
  std::optional<ImportedTopic> truth, odometer;
  std::map<std::string, TfPosition> positions;  ///< by module name
  /// nav_msgs/Odometry and geometry_msgs/PoseStamped topics not imported ("name (type)"):
  /// candidates for --truth.
  std::vector<std::string> pose_topics;
  std::vector<std::string> facts;  ///< what the import found (tf positions, conventions)
  std::vector<std::string> todo;   ///< what the import left to the user (a placeholder origin)
};

/// The module name a topic gets: the topic without its leading '/', other '/' and
/// characters outside [A-Za-z0-9_-] as '_' ("/imu/left_wheel" -> "imu_left_wheel").
std::string module_name_for_topic(const std::string& topic);

ImportResult import_recording(const std::filesystem::path& recording,
                              const std::filesystem::path& out_dir, const ImportOptions& options);

}  // namespace wheelins::ros
