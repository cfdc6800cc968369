// Fuzzes the ROS 1 bag reader of our own (records, bz2 / lz4 chunks, the index checked
// against the chunks) and the ROS 1 decoders of the four message types.
// Byte 0 chooses: even -> the rest is a .bag file, each message decoded as every type;
// odd -> the rest is one ROS 1 payload, decoded as every type (fuzz_ros.hpp).
#include "fuzz_ros.hpp"
#include "wheelins/io/ros/ros1_bag.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace wheelins;
  return fuzz::fuzz_recording<ros::Ros1BagReader, ros::Ros1Message>(ros::Serialization::kRos1, data, size);
}
