// The ROS messages `wheelins import` reads, as plain values, and the interface of
// the three recording readers (ROS 1 .bag, ROS 2 .db3, ROS 2 .mcap).
//
// Message content follows the ROS message definitions (identical in ROS 1 and 2
// for the fields used here):
//   sensor_msgs/Imu           header, orientation, angular_velocity [rad/s],
//                             linear_acceleration [m/s^2] (+ covariances, ignored)
//   nav_msgs/Odometry         header, child_frame_id, pose.pose (position, orientation),
//                             twist.twist (linear, angular; in the child frame)
//   geometry_msgs/PoseStamped header, pose (position, orientation)
//   tf2_msgs/TFMessage        transforms[]: header (parent frame), child_frame_id,
//                             transform (translation, rotation)
// Quaternions are (x, y, z, w) as in ROS. This header is also compiled as C++17
// (the ROS 1 message headers need it), so it uses nothing newer.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace wheelins::ros {

/// A ROS time: seconds and nanoseconds (ROS 1 uint32 sec; ROS 2 int32 sec).
struct Stamp {
  std::int64_t sec = 0;
  std::uint32_t nsec = 0;
  bool zero() const { return sec == 0 && nsec == 0; }
  std::int64_t ns() const { return sec * 1000000000LL + nsec; }
};

/// Seconds as the double nearest to sec.nsec (exact integer nanoseconds divided by 1e9:
/// correctly rounded while the count stays below 2^53 ns, i.e. for times below 104 days;
/// beyond that, e.g. Unix times, within a few hundred ns, the double's own resolution).
double seconds_from_ns(std::int64_t ns);

struct ImuMessage {
  Stamp stamp;
  std::string frame_id;
  std::array<double, 4> orientation{0, 0, 0, 1};
  std::array<double, 3> gyro{};   ///< angular_velocity [rad/s]
  std::array<double, 3> accel{};  ///< linear_acceleration [m/s^2]
};

/// nav_msgs/Odometry or geometry_msgs/PoseStamped.
struct PoseMessage {
  Stamp stamp;
  std::string frame_id;        ///< the frame the pose is in
  std::string child_frame_id;  ///< Odometry only: the frame of the twist
  std::array<double, 3> position{};
  std::array<double, 4> orientation{0, 0, 0, 1};
  bool has_twist = false;      ///< Odometry
  std::array<double, 3> linear{}, angular{};
};

struct Transform {
  Stamp stamp;
  std::string parent, child;
  std::array<double, 3> translation{};
  std::array<double, 4> rotation{0, 0, 0, 1};
};

enum class MessageKind { kImu, kOdometry, kPoseStamped, kTf, kOther };

/// The message kind of a ROS type name, ROS 1 ("sensor_msgs/Imu") or ROS 2
/// ("sensor_msgs/msg/Imu") spelling; kOther for everything else.
inline MessageKind message_kind(std::string type) {
  if (const auto k = type.find("/msg/"); k != std::string::npos) type.erase(k, 4);
  if (type == "sensor_msgs/Imu") return MessageKind::kImu;
  if (type == "nav_msgs/Odometry") return MessageKind::kOdometry;
  if (type == "geometry_msgs/PoseStamped") return MessageKind::kPoseStamped;
  if (type == "tf2_msgs/TFMessage") return MessageKind::kTf;
  return MessageKind::kOther;
}
/// The ROS 1 spelling of a kind's type ("sensor_msgs/Imu").
inline const char* kind_type_name(MessageKind kind) {
  switch (kind) {
    case MessageKind::kImu: return "sensor_msgs/Imu";
    case MessageKind::kOdometry: return "nav_msgs/Odometry";
    case MessageKind::kPoseStamped: return "geometry_msgs/PoseStamped";
    case MessageKind::kTf: return "tf2_msgs/TFMessage";
    case MessageKind::kOther: break;
  }
  return "another type";
}

struct TopicInfo {
  std::string name;
  std::string type;       ///< as stored in the recording
  MessageKind kind = MessageKind::kOther;
  std::uint64_t count = 0;  ///< messages, when the format says (0: unknown)
};

/// One message, decoded when its topic was asked for.
struct Message {
  std::size_t topic = 0;        ///< index into RecordingReader::topics()
  std::uint64_t index = 0;      ///< 0-based index among the messages of its topic
  std::int64_t receive_ns = 0;  ///< the recorder's receive time (bag time) [ns]
  ImuMessage imu;               ///< kind kImu
  PoseMessage pose;             ///< kOdometry, kPoseStamped
  std::vector<Transform> tf;    ///< kTf
};

/// Streams the messages of a recording in file order. Errors (unreadable file,
/// truncated data, a message that does not decode as its type) throw InputError
/// naming the file, and the topic and message index where one is known.
class RecordingReader {
 public:
  virtual ~RecordingReader() = default;
  virtual const std::vector<TopicInfo>& topics() const = 0;
  /// Decode only the messages of topics with wanted[topic] set (sized like topics()).
  virtual void select(const std::vector<bool>& wanted) = 0;
  /// The next selected message; false at the end.
  virtual bool next(Message& out) = 0;
  virtual std::string format() const = 0;  ///< "ROS 1 bag", "ROS 2 sqlite3", "ROS 2 MCAP"
};

/// Which reader a path needs: a .bag file (ROS 1), a .db3 or .mcap file, or a ROS 2 bag
/// directory (metadata.yaml with .db3 or .mcap files, read in name order).
std::unique_ptr<RecordingReader> open_recording(const std::filesystem::path& path);

// The readers (io/ros/ros1_bag.cpp, db3.cpp, mcap.cpp).
std::unique_ptr<RecordingReader> open_ros1_bag(const std::filesystem::path& file);
std::unique_ptr<RecordingReader> open_ros2_db3(const std::vector<std::filesystem::path>& files);
std::unique_ptr<RecordingReader> open_ros2_mcap(const std::vector<std::filesystem::path>& files);

}  // namespace wheelins::ros
