// ROS 2 bags for the tests: a CDR serialiser, an sqlite3 bag and an MCAP file, written
// from the specifications independently of the readers in src/wheelins/io/ros/.
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>

#include "bag_writers.hpp"
#include "wheelins/io/ros/mcap.hpp"  // crc32 only

namespace wheelins::test_ros {
namespace {

class Cdr {
 public:
  explicit Cdr(bool big) : big_(big) { b_ = {0x00, static_cast<std::uint8_t>(big ? 0x00 : 0x01), 0, 0}; }
  void pad(std::size_t n) {
    while ((b_.size() - 4) % n) b_.push_back(0);
  }
  void raw(const void* p, std::size_t n) {
    pad(n);
    const auto* c = static_cast<const std::uint8_t*>(p);
    for (std::size_t i = 0; i < n; ++i) b_.push_back(c[big_ ? n - 1 - i : i]);
  }
  void u32(std::uint32_t v) { raw(&v, 4); }
  void i32(std::int32_t v) { raw(&v, 4); }
  void f64(double v) { raw(&v, 8); }
  void str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    for (char c : s) b_.push_back(static_cast<std::uint8_t>(c));
    b_.push_back(0);
  }
  void time(const ros::Stamp& s) {
    i32(static_cast<std::int32_t>(s.sec));
    u32(s.nsec);
  }
  void vec(const double* v, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) f64(v[i]);
  }
  void zeros(std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) f64(0.0);
  }
  std::vector<std::uint8_t> b_;

 private:
  bool big_;
};

const char* ros2_type(ros::MessageKind k) {
  switch (k) {
    case ros::MessageKind::kImu: return "sensor_msgs/msg/Imu";
    case ros::MessageKind::kOdometry: return "nav_msgs/msg/Odometry";
    case ros::MessageKind::kPoseStamped: return "geometry_msgs/msg/PoseStamped";
    case ros::MessageKind::kTf: return "tf2_msgs/msg/TFMessage";
    default: throw std::invalid_argument("ros2_type: kOther");
  }
}

void put(std::vector<std::uint8_t>& b, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_str(std::vector<std::uint8_t>& b, const std::string& s) {
  put(b, s.size(), 4);
  b.insert(b.end(), s.begin(), s.end());
}
void record(std::vector<std::uint8_t>& out, std::uint8_t op, const std::vector<std::uint8_t>& content) {
  out.push_back(op);
  put(out, content.size(), 8);
  out.insert(out.end(), content.begin(), content.end());
}

}  // namespace

std::vector<std::uint8_t> cdr_payload(const OutMessage& m, bool big_endian) {
  Cdr c(big_endian);
  switch (m.kind) {
    case ros::MessageKind::kImu:
      c.time(m.imu.stamp);
      c.str(m.imu.frame_id);
      c.vec(m.imu.orientation.data(), 4);
      c.zeros(9);
      c.vec(m.imu.gyro.data(), 3);
      c.zeros(9);
      c.vec(m.imu.accel.data(), 3);
      c.zeros(9);
      break;
    case ros::MessageKind::kOdometry:
      c.time(m.pose.stamp);
      c.str(m.pose.frame_id);
      c.str(m.pose.child_frame_id);
      c.vec(m.pose.position.data(), 3);
      c.vec(m.pose.orientation.data(), 4);
      c.zeros(36);
      c.vec(m.pose.linear.data(), 3);
      c.vec(m.pose.angular.data(), 3);
      c.zeros(36);
      break;
    case ros::MessageKind::kPoseStamped:
      c.time(m.pose.stamp);
      c.str(m.pose.frame_id);
      c.vec(m.pose.position.data(), 3);
      c.vec(m.pose.orientation.data(), 4);
      break;
    case ros::MessageKind::kTf:
      c.u32(static_cast<std::uint32_t>(m.tf.size()));
      for (const auto& t : m.tf) {
        c.time(t.stamp);
        c.str(t.parent);
        c.str(t.child);
        c.vec(t.translation.data(), 3);
        c.vec(t.rotation.data(), 4);
      }
      break;
    default: throw std::invalid_argument("cdr_payload: kOther");
  }
  return c.b_;
}

void write_ros2_db3(const std::filesystem::path& file, const std::vector<OutMessage>& msgs, bool big_endian) {
  std::filesystem::remove(file);
  sqlite3* db = nullptr;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK) throw std::runtime_error("sqlite3_open");
  auto exec = [&](const std::string& sql) {
    char* err = nullptr;
    if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      std::string e = err ? err : "?";
      sqlite3_free(err);
      throw std::runtime_error(sql + ": " + e);
    }
  };
  exec("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
       "INSERT INTO schema VALUES(3, 'humble');"
       "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);"
       "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
       "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
       "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
       "data BLOB NOT NULL);"
       "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
       "BEGIN TRANSACTION;");
  std::map<std::string, int> ids;
  sqlite3_stmt* topic = nullptr;
  sqlite3_stmt* msg = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO topics VALUES(?, ?, ?, 'cdr', '')", -1, &topic, nullptr);
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", -1, &msg, nullptr);
  for (const OutMessage& m : msgs) {
    auto it = ids.find(m.topic);
    if (it == ids.end()) {
      const int id = static_cast<int>(ids.size()) + 1;
      it = ids.emplace(m.topic, id).first;
      sqlite3_bind_int(topic, 1, id);
      sqlite3_bind_text(topic, 2, m.topic.c_str(), -1, SQLITE_TRANSIENT);
      sqlite3_bind_text(topic, 3, ros2_type(m.kind), -1, SQLITE_STATIC);
      if (sqlite3_step(topic) != SQLITE_DONE) throw std::runtime_error("insert topic");
      sqlite3_reset(topic);
    }
    const auto data = cdr_payload(m, big_endian);
    sqlite3_bind_int(msg, 1, it->second);
    sqlite3_bind_int64(msg, 2, m.receive_ns);
    sqlite3_bind_blob(msg, 3, data.data(), static_cast<int>(data.size()), SQLITE_TRANSIENT);
    if (sqlite3_step(msg) != SQLITE_DONE) throw std::runtime_error("insert message");
    sqlite3_reset(msg);
  }
  sqlite3_finalize(topic);
  sqlite3_finalize(msg);
  exec("COMMIT;");
  sqlite3_close(db);
}

void write_ros2_mcap(const std::filesystem::path& file, const std::vector<OutMessage>& msgs, const McapOptions& o) {
  std::vector<std::uint8_t> out = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
  std::vector<std::uint8_t> c;
  put_str(c, "ros2");
  put_str(c, "wheelins tests");
  record(out, 0x01, c);

  std::map<std::string, std::uint16_t> channel;
  std::map<ros::MessageKind, std::uint16_t> schema;
  std::vector<std::uint8_t> chunk;  // records of the open chunk
  std::uint64_t t_start = 0, t_end = 0;
  std::size_t in_chunk = 0;
  auto flush = [&]() {
    if (chunk.empty()) return;
    std::vector<std::uint8_t> packed;
    if (o.compression == "zstd") {
      packed.resize(ZSTD_compressBound(chunk.size()));
      packed.resize(ZSTD_compress(packed.data(), packed.size(), chunk.data(), chunk.size(), 3));
    } else if (o.compression == "lz4") {
      packed.resize(LZ4F_compressFrameBound(chunk.size(), nullptr));
      packed.resize(LZ4F_compressFrame(packed.data(), packed.size(), chunk.data(), chunk.size(), nullptr));
    } else {
      packed = chunk;
    }
    std::vector<std::uint8_t> r;
    put(r, t_start, 8);
    put(r, t_end, 8);
    put(r, chunk.size(), 8);
    put(r, o.crc ? ros::crc32(chunk.data(), chunk.size()) : 0, 4);
    put_str(r, o.compression);
    put(r, packed.size(), 8);
    r.insert(r.end(), packed.begin(), packed.end());
    record(out, 0x06, r);
    chunk.clear();
    in_chunk = 0;
  };
  for (const OutMessage& m : msgs) {
    std::vector<std::uint8_t>& dst = o.messages_per_chunk ? chunk : out;
    if (!schema.count(m.kind)) {
      const auto id = static_cast<std::uint16_t>(schema.size() + 1);
      schema[m.kind] = id;
      std::vector<std::uint8_t> s;
      put(s, id, 2);
      put_str(s, ros2_type(m.kind));
      put_str(s, "ros2msg");
      put_str(s, "");  // the definition text: not needed by the reader
      record(dst, 0x03, s);
    }
    if (!channel.count(m.topic)) {
      const auto id = static_cast<std::uint16_t>(channel.size());
      channel[m.topic] = id;
      std::vector<std::uint8_t> s;
      put(s, id, 2);
      put(s, schema[m.kind], 2);
      put_str(s, m.topic);
      put_str(s, "cdr");
      put(s, 0, 4);  // empty metadata map
      record(dst, 0x04, s);
    }
    std::vector<std::uint8_t> s;
    put(s, channel[m.topic], 2);
    put(s, 0, 4);
    put(s, static_cast<std::uint64_t>(m.receive_ns), 8);
    put(s, static_cast<std::uint64_t>(m.receive_ns), 8);
    const auto data = cdr_payload(m);
    s.insert(s.end(), data.begin(), data.end());
    if (in_chunk == 0) t_start = static_cast<std::uint64_t>(m.receive_ns);
    t_end = static_cast<std::uint64_t>(m.receive_ns);
    record(dst, 0x05, s);
    if (o.messages_per_chunk && ++in_chunk == o.messages_per_chunk) flush();
  }
  flush();
  if (o.summary_end) {
    std::vector<std::uint8_t> s;
    put(s, 0, 4);
    record(out, 0x0F, s);  // DataEnd
    s.clear();
    put(s, 0, 8);
    put(s, 0, 8);
    put(s, 0, 4);
    record(out, 0x02, s);  // Footer (no summary)
    const std::uint8_t magic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    out.insert(out.end(), magic, magic + 8);
  }
  std::ofstream f(file, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size()));
  if (!f) throw std::runtime_error("write " + file.string());
}

}  // namespace wheelins::test_ros
