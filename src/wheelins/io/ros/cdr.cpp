// The CDR (XCDR1) reader (cdr.hpp) and the decoders of the four ROS 2 message types
// wheelins import reads: Imu, Odometry, PoseStamped, TFMessage.
#include "wheelins/io/ros/cdr.hpp"

#include <cstdio>
#include <cstring>

namespace wheelins::ros {

namespace {
constexpr std::size_t kHeader = 4;
}

CdrReader::CdrReader(const std::uint8_t* data, std::size_t size, Serialization s)
    : data_(data), size_(size), ros1_(s == Serialization::kRos1) {
  if (ros1_) {
    pos_ = 0;
    return;
  }
  if (size < kHeader)
    throw CdrError("CDR payload of " + std::to_string(size) +
                   " bytes is shorter than its 4-byte encapsulation header");
  const unsigned id = (unsigned(data[0]) << 8) | data[1];
  if (id != 0x0000 && id != 0x0001) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "CDR encapsulation 0x%04x is not plain CDR (0x0000 big-, 0x0001 little-endian)", id);
    throw CdrError(buf);
  }
  little_ = id == 0x0001;
}

void CdrReader::align(std::size_t n) {
  if (ros1_) return;
  const std::size_t rel = pos_ - kHeader;
  const std::size_t pad = (n - rel % n) % n;
  pos_ = pad > size_ - pos_ ? size_ : pos_ + pad;
}

const std::uint8_t* CdrReader::take(std::size_t n, const char* field) {
  if (n > size_ - pos_)
    throw CdrError(std::string(ros1_ ? "ROS 1" : "CDR") + " payload ends at byte " + std::to_string(size_) + " while reading " + field +
                   " (" + std::to_string(n) + " bytes at byte " + std::to_string(pos_) + ")");
  const std::uint8_t* p = data_ + pos_;
  pos_ += n;
  return p;
}

std::uint32_t CdrReader::u32(const char* field) {
  align(4);
  const std::uint8_t* p = take(4, field);
  return little_ ? (std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24)
                 : (std::uint32_t(p[3]) | std::uint32_t(p[2]) << 8 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[0]) << 24);
}

std::int32_t CdrReader::i32(const char* field) { return static_cast<std::int32_t>(u32(field)); }

double CdrReader::f64(const char* field) {
  align(8);
  const std::uint8_t* p = take(8, field);
  std::uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= std::uint64_t(p[little_ ? i : 7 - i]) << (8 * i);
  double v;
  std::memcpy(&v, &bits, 8);
  return v;
}

void CdrReader::f64s(double* out, std::size_t n, const char* field) {
  for (std::size_t i = 0; i < n; ++i) out[i] = f64(field);
}

void CdrReader::skip_f64(std::size_t n, const char* field) {
  if (n == 0) return;
  align(8);
  take(8 * n, field);
}

std::string CdrReader::str(const char* field) {
  const std::uint32_t n = u32(field);
  if (n == 0) return {};  // some writers emit 0 for the empty string
  const std::uint8_t* p = take(n, field);
  if (ros1_) return std::string(reinterpret_cast<const char*>(p), n);
  if (p[n - 1] != 0) throw CdrError(std::string("CDR string ") + field + " is not NUL-terminated");
  return std::string(reinterpret_cast<const char*>(p), n - 1);
}

Stamp CdrReader::time(const char* field) {
  Stamp s;
  s.sec = ros1_ ? std::int64_t{u32(field)} : std::int64_t{i32(field)};
  s.nsec = u32(field);
  if (s.nsec >= 1000000000u)
    throw CdrError(std::string(field) + ": nanosec " + std::to_string(s.nsec) + " is not below 1e9");
  return s;
}

// std_msgs/Header: (ROS 1: uint32 seq), time stamp, string frame_id.
void CdrReader::header(Stamp& stamp, std::string& frame) {
  if (ros1_) u32("header.seq");
  stamp = time("header.stamp");
  frame = str("header.frame_id");
}

namespace {
void vec3(CdrReader& r, std::array<double, 3>& v, const char* field) { r.f64s(v.data(), 3, field); }
void quat(CdrReader& r, std::array<double, 4>& q, const char* field) { r.f64s(q.data(), 4, field); }

ImuMessage imu(CdrReader& r) {
  ImuMessage m;
  r.header(m.stamp, m.frame_id);
  quat(r, m.orientation, "orientation");
  r.skip_f64(9, "orientation_covariance");
  vec3(r, m.gyro, "angular_velocity");
  r.skip_f64(9, "angular_velocity_covariance");
  vec3(r, m.accel, "linear_acceleration");
  r.skip_f64(9, "linear_acceleration_covariance");
  return m;
}

PoseMessage odometry(CdrReader& r) {
  PoseMessage m;
  r.header(m.stamp, m.frame_id);
  m.child_frame_id = r.str("child_frame_id");
  vec3(r, m.position, "pose.pose.position");
  quat(r, m.orientation, "pose.pose.orientation");
  r.skip_f64(36, "pose.covariance");
  vec3(r, m.linear, "twist.twist.linear");
  vec3(r, m.angular, "twist.twist.angular");
  r.skip_f64(36, "twist.covariance");
  m.has_twist = true;
  return m;
}

PoseMessage pose_stamped(CdrReader& r) {
  PoseMessage m;
  r.header(m.stamp, m.frame_id);
  vec3(r, m.position, "pose.position");
  quat(r, m.orientation, "pose.orientation");
  return m;
}

std::vector<Transform> tf(CdrReader& r) {
  const std::uint32_t n = r.u32("transforms (count)");
  // Each TransformStamped takes at least 8 + 4 + 4 + 56 bytes: a count beyond what the
  // buffer can hold is malformed (and must not size an allocation).
  if (n > r.remaining() / 72)
    throw CdrError("sequence transforms: " + std::to_string(n) + " elements cannot fit in " +
                   std::to_string(r.remaining()) + " bytes");
  std::vector<Transform> out(n);
  for (auto& t : out) {
    r.header(t.stamp, t.parent);
    t.child = r.str("transforms[].child_frame_id");
    vec3(r, t.translation, "transforms[].transform.translation");
    quat(r, t.rotation, "transforms[].transform.rotation");
  }
  return out;
}

void decode(MessageKind kind, CdrReader& r, Message& out) {
  switch (kind) {
    case MessageKind::kImu: out.imu = imu(r); return;
    case MessageKind::kOdometry: out.pose = odometry(r); return;
    case MessageKind::kPoseStamped: out.pose = pose_stamped(r); return;
    case MessageKind::kTf: out.tf = tf(r); return;
    case MessageKind::kOther: break;
  }
  throw std::logic_error("decode: no decoder for this message type");
}

}  // namespace

ImuMessage decode_imu(const std::uint8_t* data, std::size_t size) {
  CdrReader r(data, size);
  return imu(r);
}
PoseMessage decode_odometry(const std::uint8_t* data, std::size_t size) {
  CdrReader r(data, size);
  return odometry(r);
}
PoseMessage decode_pose_stamped(const std::uint8_t* data, std::size_t size) {
  CdrReader r(data, size);
  return pose_stamped(r);
}
std::vector<Transform> decode_tf(const std::uint8_t* data, std::size_t size) {
  CdrReader r(data, size);
  return tf(r);
}

void decode_cdr(MessageKind kind, const std::uint8_t* data, std::size_t size, Message& out) {
  CdrReader r(data, size);
  decode(kind, r, out);
}

void decode_ros1(MessageKind kind, const std::uint8_t* data, std::size_t size, Message& out) {
  CdrReader r(data, size, Serialization::kRos1);
  decode(kind, r, out);
}

}  // namespace wheelins::ros
