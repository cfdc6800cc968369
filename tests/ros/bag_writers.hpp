// Test-side writers of ROS recordings, independent of the readers under test:
// ROS 1 bags with the ROS bag storage library (ros1_writer.cpp, C++17), ROS 2 sqlite3
// and MCAP bags with a CDR serialiser of their own (ros2_writers.cpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "wheelins/io/ros/messages.hpp"

namespace wheelins::test_ros {

/// One message to write; the field that `kind` names is used.
struct OutMessage {
  std::string topic;
  ros::MessageKind kind = ros::MessageKind::kImu;
  std::int64_t receive_ns = 0;
  ros::ImuMessage imu;
  ros::PoseMessage pose;           ///< kOdometry, kPoseStamped
  std::vector<ros::Transform> tf;  ///< kTf
};

/// ROS 1 bag; compression "none", "lz4" or "bz2". Written with the ROS bag library, so only in
/// a build with WHEELINS_ROS1=ON (cmake/ros_tests.cmake); a test that needs it skips without.
#if WHEELINS_HAVE_ROS1
void write_ros1_bag(const std::filesystem::path& file, const std::vector<OutMessage>& msgs,
                    const std::string& compression = "none");
#endif

/// The CDR (XCDR1) payload of a message, little- or big-endian.
std::vector<std::uint8_t> cdr_payload(const OutMessage& m, bool big_endian = false);

/// ROS 2 sqlite3 bag (the Humble schema). Payloads big-endian when asked.
void write_ros2_db3(const std::filesystem::path& file, const std::vector<OutMessage>& msgs,
                    bool big_endian = false);

struct McapOptions {
  std::string compression = "zstd";  ///< "", "zstd" or "lz4"
  std::size_t messages_per_chunk = 500;  ///< 0: no chunks (records in the data section)
  bool crc = true;                   ///< write the chunks' CRC-32
  bool summary_end = true;           ///< DataEnd, Footer and the closing magic
};
/// ROS 2 MCAP file (profile ros2, schemas ros2msg, messages cdr).
void write_ros2_mcap(const std::filesystem::path& file, const std::vector<OutMessage>& msgs,
                     const McapOptions& options = {});

}  // namespace wheelins::test_ros
