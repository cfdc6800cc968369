// The ROS 1 side of `wheelins live --ros` (docs/live.md): the node's connection to the master,
// its subscriptions and publications, behind plain types. Its source is compiled as C++17
// (the ROS 1 message headers use what C++20 removed) and only when the build has Debian's
// ROS 1 packages (WHEELINS_ROS1); cmd_live.cpp sees only this header.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace wheelins::ros1 {

/// One sensor_msgs/Imu message as it arrived.
struct ImuMessage {
  int module = 0;            ///< index of the topic in NodeSetup::topics
  std::uint32_t seq = 0;     ///< the header's sequence number
  double t = 0.0;            ///< header.stamp [s]
  double gyro[3] = {0, 0, 0}, accel[3] = {0, 0, 0};  ///< angular_velocity, linear_acceleration
  std::string frame_id;
  double arrival = 0.0;      ///< the steady clock when roscpp received it (its receipt time) [s]
};

/// One nav_msgs/Odometry message (and its transform).
struct Odometry {
  double t = 0.0;
  double position[3] = {0, 0, 0};
  double orientation[4] = {0, 0, 0, 1};  ///< x, y, z, w
  std::array<double, 36> pose_covariance{};
  double linear[3] = {0, 0, 0}, angular[3] = {0, 0, 0};
  std::array<double, 36> twist_covariance{};
};

/// One diagnostic_msgs/DiagnosticStatus.
struct Diagnostic {
  enum Level : std::uint8_t { kOk = 0, kWarn = 1, kError = 2, kStale = 3 };
  Level level = kOk;
  std::string name, message, hardware_id;
  std::vector<std::pair<std::string, std::string>> values;
};

struct NodeSetup {
  std::vector<std::string> topics;  ///< one sensor_msgs/Imu topic per module
  std::string odom_topic = "odom", odom_frame = "odom", base_frame = "base_link";
  bool publish_tf = true;
  int queue = 2000;  ///< messages a subscription holds before the oldest are dropped
};

/// A node connected to the master. The implementation (ros1_node.cpp, with roscpp) is a
/// plugin the program loads only for `live --ros` (connect()), so that the program itself links
/// no ROS library (RosFreeBuild.TheProgramLinksNothingOfRos) and runs where ROS is not installed.
class Node {
 public:
  virtual ~Node() = default;
  /// The node's private parameters (~name): scalars as text, a dictionary flattened to
  /// "name.key" entries, a list as its items joined by commas.
  virtual std::map<std::string, std::string> private_parameters() const = 0;
  virtual std::string name() const = 0;
  /// Subscribes to the topics and advertises the odometry, /tf and /diagnostics. `on_imu` is
  /// called for each message on roscpp's receive thread as soon as the message is read (no
  /// hand-over to another thread: one wake-up per message less), so it runs concurrently with
  /// the caller's thread; what it throws is rethrown by spin(), and no further message is given.
  virtual void start(const NodeSetup& setup, std::function<void(const ImuMessage&)> on_imu) = 0;
  /// Unsubscribes from the topics: `on_imu` is not called after it returns (a call under way
  /// is waited for). Idempotent.
  virtual void stop() = 0;
  /// Waits up to `timeout` s (handling ROS's own callbacks meanwhile); false once ROS shuts down
  /// (the master asked; Ctrl-C is the caller's). Rethrows what `on_imu` threw.
  virtual bool spin(double timeout) = 0;
  virtual void publish(const Odometry& odom) = 0;
  /// The statuses as one diagnostic_msgs/DiagnosticArray stamped `stamp` (<= 0: ROS's now).
  virtual void publish(const std::vector<Diagnostic>& status, double stamp) = 0;
  /// For each subscribed topic (NodeSetup::topics' order): the type the master lists for it
  /// when that is not sensor_msgs/Imu (a publisher of another type), else empty.
  virtual std::vector<std::string> wrong_types() const = 0;
};

/// The plugin's entry point (extern "C", found with dlsym): connects to the master
/// (ROS_MASTER_URI) as node `name` with the command line's ROS arguments (`__name:=`,
/// remappings), waiting up to `wait` seconds for it. Null with `error` set when it cannot.
using ConnectFunction = Node* (*)(const std::string& name, const std::vector<std::string>& ros_args, double wait,
                                  std::string& error);
constexpr const char* kConnectSymbol = "wheelins_ros1_connect";
constexpr const char* kPluginFile = "libwheelins_ros1_node.so";

}  // namespace wheelins::ros1
