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
//   OUT/manifest.yaml      drafted as `wheelins manifest OUT` drafts it (io/manifest_draft.hpp);
//                          module positions from /tf_static where it has the IMU frames
//
// Every message is checked: a header stamp of zero, stamps that do not increase within
// a topic, and NaN or infinite values are InputErrors naming the file, the topic and the
// 0-based message index; so are a topic of the wrong type and a truncated recording.
// Nothing is left behind on an error (all files appear together at the end).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/io/manifest_draft.hpp"
#include "wheelins/nav/earth.hpp"

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

struct ImportResult {
  std::string format;  ///< the recording's format
  std::vector<ImportedTopic> imu;
  std::optional<ImportedTopic> truth, odometer;
  std::filesystem::path manifest_file;
  ManifestDraft draft;
  std::vector<std::string> facts;  ///< what the import found (tf positions, conventions)
};

/// The module name a topic gets: the topic without its leading '/', other '/' and
/// characters outside [A-Za-z0-9_-] as '_' ("/imu/left_wheel" -> "imu_left_wheel").
std::string module_name_for_topic(const std::string& topic);

ImportResult import_recording(const std::filesystem::path& recording,
                              const std::filesystem::path& out_dir, const ImportOptions& options);

}  // namespace wheelins::ros
