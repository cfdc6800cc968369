// Fuzzes the ROS 2 readers of our own: the MCAP container (records, chunks with zstd /
// lz4 compression and CRC) and the CDR decoders of the four message types.
// Byte 0 chooses: even -> the rest is an MCAP file, each message decoded as every type;
// odd -> the rest is one CDR payload, decoded as every type.
#include "fuzz_common.hpp"
#include "wheelins/io/ros/cdr.hpp"
#include "wheelins/io/ros/mcap.hpp"

using namespace wheelins;

namespace {
void decode_all(const std::uint8_t* p, std::size_t n) {
  for (ros::MessageKind k : {ros::MessageKind::kImu, ros::MessageKind::kOdometry, ros::MessageKind::kPoseStamped,
                             ros::MessageKind::kTf}) {
    ros::Message m;
    try {
      ros::decode_cdr(k, p, n, m);
    } catch (const ros::CdrError&) {
    }
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  if (data[0] & 1) {
    decode_all(data + 1, size - 1);
    return 0;
  }
  try {
    // A 1 MiB chunk bound keeps a declared size from costing the fuzzer its memory.
    ros::McapReader r("fuzz input", data + 1, size - 1, 1u << 20);
    ros::McapMessage m;
    while (r.next(m)) decode_all(m.data, m.size);
  } catch (const InputError&) {
  }
  return 0;
}
