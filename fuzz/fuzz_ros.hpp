// What the fuzzers of the ROS recording readers share: byte 0 of the input chooses
// between a whole recording (even: the rest is the file, each message decoded as every
// type) and one payload (odd: the rest decoded as every type). Malformed data are
// InputError / CdrError; anything else escapes and libFuzzer reports it.
#pragma once

#include "fuzz_common.hpp"
#include "wheelins/io/ros/cdr.hpp"

namespace wheelins::fuzz {

inline void decode_as_every_type(ros::Serialization s, const std::uint8_t* p, std::size_t n) {
  for (ros::MessageKind k : {ros::MessageKind::kImu, ros::MessageKind::kOdometry, ros::MessageKind::kPoseStamped,
                             ros::MessageKind::kTf}) {
    ros::Message m;
    try {
      if (s == ros::Serialization::kRos1) ros::decode_ros1(k, p, n, m);
      else ros::decode_cdr(k, p, n, m);
    } catch (const ros::CdrError&) {
    }
  }
}

/// One input for a container reader `Reader` (constructed from a name and bytes, with a
/// 1 MiB chunk bound so that a declared size cannot cost the fuzzer its memory) whose
/// next(Message&) yields messages with data/size.
template <class Reader, class Message>
int fuzz_recording(ros::Serialization s, const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  if (data[0] & 1) {
    decode_as_every_type(s, data + 1, size - 1);
    return 0;
  }
  try {
    Reader r("fuzz input", data + 1, size - 1, 1u << 20);
    Message m;
    while (r.next(m)) decode_as_every_type(s, m.data, m.size);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace wheelins::fuzz
