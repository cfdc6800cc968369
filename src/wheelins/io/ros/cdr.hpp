// The ROS 2 message payload: OMG CDR, version 1 (XCDR1, "plain CDR"), as the ROS 2
// middlewares serialise messages into bags (serialization_format / message_encoding
// "cdr").
//
// Layout (OMG DDS-XTypes 1.3, 7.4.3 "Data Representation", and CORBA 3.x, 9.3
// "CDR Transfer Syntax"):
//   * a 4-byte encapsulation header: representation identifier (2 bytes, big-endian)
//     0x0000 CDR_BE or 0x0001 CDR_LE, then 2 option bytes (ignored);
//   * members in declaration order, each primitive aligned to its own size (1, 2, 4,
//     8 bytes) counted from the end of the encapsulation header, in the byte order
//     the identifier names;
//   * string: uint32 length including the terminating NUL, the bytes, the NUL;
//   * sequence<T>: uint32 element count, then the elements; T[N]: the N elements.
// The decoders below follow the ROS 2 message definitions (see messages.hpp); an
// ROS 2 builtin_interfaces/Time is int32 sec, uint32 nanosec.
// The same reader takes ROS 1 payloads (the ROS 1 serialisation: no encapsulation
// header, no alignment, little-endian; string: uint32 length, the bytes, no NUL;
// std_msgs/Header: uint32 seq, time stamp (uint32 sec, uint32 nsec), string frame_id),
// so one set of decoders serves both (decode_cdr, decode_ros1).
// Malformed input throws CdrError naming the field and the byte offset; nothing is
// read past the end of the buffer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "wheelins/io/ros/messages.hpp"

namespace wheelins::ros {

class CdrError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The serialisation of a payload: ROS 2's CDR or ROS 1's.
enum class Serialization { kCdr, kRos1 };

class CdrReader {
 public:
  /// kCdr: reads the encapsulation header; throws CdrError for a short buffer or an
  /// identifier other than CDR_BE / CDR_LE. kRos1: the payload starts at byte 0.
  CdrReader(const std::uint8_t* data, std::size_t size, Serialization s = Serialization::kCdr);

  std::uint32_t u32(const char* field);
  std::int32_t i32(const char* field);
  double f64(const char* field);
  std::string str(const char* field);
  void f64s(double* out, std::size_t n, const char* field);
  void skip_f64(std::size_t n, const char* field);
  Stamp time(const char* field);
  /// std_msgs/Header (ROS 1: with its seq, skipped).
  void header(Stamp& stamp, std::string& frame_id);
  /// Bytes not yet read (trailing padding is allowed).
  std::size_t remaining() const { return size_ - pos_; }
  bool little_endian() const { return little_; }

 private:
  void align(std::size_t n);
  const std::uint8_t* take(std::size_t n, const char* field);
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 4;  ///< offset in data_ (alignment counts from 4)
  bool little_ = true;
  bool ros1_ = false;
};

ImuMessage decode_imu(const std::uint8_t* data, std::size_t size);
PoseMessage decode_odometry(const std::uint8_t* data, std::size_t size);
PoseMessage decode_pose_stamped(const std::uint8_t* data, std::size_t size);
std::vector<Transform> decode_tf(const std::uint8_t* data, std::size_t size);

/// Decodes a payload of `kind` into `out` (CdrError for malformed data, an
/// std::logic_error for kOther).
void decode_cdr(MessageKind kind, const std::uint8_t* data, std::size_t size, Message& out);
/// The same for a ROS 1 payload (Serialization::kRos1).
void decode_ros1(MessageKind kind, const std::uint8_t* data, std::size_t size, Message& out);

}  // namespace wheelins::ros
