// Fuzzes the ROS 2 readers of our own: the MCAP container (records, chunks with zstd /
// lz4 compression and CRC) and the CDR decoders of the four message types.
// Byte 0 chooses: even -> the rest is an MCAP file, each message decoded as every type;
// odd -> the rest is one CDR payload, decoded as every type (fuzz_ros.hpp).
#include "fuzz_ros.hpp"
#include "wheelins/io/ros/mcap.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace wheelins;
  return fuzz::fuzz_recording<ros::McapReader, ros::McapMessage>(ros::Serialization::kCdr, data, size);
}
