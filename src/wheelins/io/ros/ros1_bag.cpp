// The ROS 1 bag reader (ros1_bag.hpp), and the RecordingReader of `wheelins import` on
// top of it: connections' types checked by their MD5 sums, messages decoded by the ROS 1
// decoders of cdr.hpp.
#include "wheelins/io/ros/ros1_bag.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "wheelins/io/ros/cdr.hpp"
#include "wheelins/io/ros/decompress.hpp"
#include "wheelins/io/ros/messages.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::ros {
namespace fs = std::filesystem;

namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::size_t kMagicLen = sizeof kMagic - 1;
enum Op : std::uint8_t {
  kMessageData = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05, kChunkInfo = 0x06,
  kConnection = 0x07
};
constexpr std::uint64_t kMaxHeader = 1u << 20;  // a record header: a few fields

const char* op_name(int op) {
  switch (op) {
    case kMessageData: return "Message data";
    case kBagHeader: return "Bag header";
    case kIndexData: return "Index data";
    case kChunk: return "Chunk";
    case kChunkInfo: return "Chunk info";
    case kConnection: return "Connection";
    default: return "record";
  }
}

using Fields = std::vector<std::pair<std::string_view, Ros1BagReader::Field>>;

/// The fields of a header block (a record's header, or a connection record's data).
Fields parse_fields(const std::uint8_t* p, std::size_t n) {
  Fields f;
  std::size_t pos = 0;
  while (pos < n) {
    if (n - pos < 4) throw std::runtime_error("header ends inside a field's length");
    const std::uint64_t len = read_le(p + pos, 4);
    pos += 4;
    if (len > n - pos)
      throw std::runtime_error("header field of " + std::to_string(len) + " bytes runs past the header's end (" +
                               std::to_string(n - pos) + " bytes left)");
    const auto* s = reinterpret_cast<const char*>(p + pos);
    const void* eq = std::memchr(s, '=', len);
    if (!eq) throw std::runtime_error("header field without '='");
    const auto k = static_cast<std::size_t>(static_cast<const char*>(eq) - s);
    f.push_back({std::string_view(s, k), Ros1BagReader::Field{p + pos + k + 1, len - k - 1}});
    pos += len;
  }
  return f;
}

const Ros1BagReader::Field* find(const Fields& f, std::string_view name) {
  for (const auto& [k, v] : f)
    if (k == name) return &v;
  return nullptr;
}

std::uint64_t uint_field(const Fields& f, const char* name, int bytes) {
  const Ros1BagReader::Field* v = find(f, name);
  if (!v) throw std::runtime_error(std::string("header has no '") + name + "' field");
  if (v->n != static_cast<std::size_t>(bytes))
    throw std::runtime_error(std::string("header field '") + name + "' has " + std::to_string(v->n) +
                             " bytes, expected " + std::to_string(bytes));
  return read_le(v->p, bytes);
}

std::string string_field(const Fields& f, const char* name) {
  const Ros1BagReader::Field* v = find(f, name);
  if (!v) throw std::runtime_error(std::string("header has no '") + name + "' field");
  return std::string(reinterpret_cast<const char*>(v->p), v->n);
}

}  // namespace

/// One record: its header's fields and its data.
struct Ros1BagReader::Record {
  int op = -1;
  Fields fields;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

Ros1BagReader::Ros1BagReader(const fs::path& file, std::uint64_t max_chunk_bytes)
    : src_(file, "a ROS 1 .bag file"), max_chunk_(max_chunk_bytes) {
  start();
}

Ros1BagReader::Ros1BagReader(std::string name, const std::uint8_t* data, std::size_t size,
                             std::uint64_t max_chunk_bytes)
    : src_(std::move(name), data, size), max_chunk_(max_chunk_bytes) {
  start();
}

void Ros1BagReader::fail(std::uint64_t offset, const std::string& what) const {
  src_.fail(offset, what + " (corrupt or truncated bag?)");
}

void Ros1BagReader::fail_in_chunk(std::uint64_t at, const std::string& what) const {
  fail(chunk_offset_, "Chunk, at byte " + std::to_string(at) + " of its data: " + what);
}

void Ros1BagReader::start() {
  std::uint8_t magic[kMagicLen];
  if (!src_.read(magic, kMagicLen) || std::memcmp(magic, kMagic, kMagicLen) != 0) {
    if (src_.pos() == kMagicLen && std::memcmp(magic, "#ROSBAG V", 9) == 0)
      fail(0, "a ROS bag of another format version than 2.0, which this reader does not read");
    fail(0, "not a ROS 1 bag (no \"#ROSBAG V2.0\" line at the start)");
  }
  if (src_.left() == 0) fail(src_.pos(), "the file ends after its version line (no bag header)");
  const std::uint64_t at = src_.pos();
  std::uint8_t len4[4];
  if (!src_.read(len4, 4)) fail(at, "the file ends inside the bag header");
  const std::uint64_t hlen = read_le(len4, 4);
  if (hlen > kMaxHeader || hlen > src_.left()) fail(at, "Bag header's header length " + std::to_string(hlen) + " runs past the end of the file");
  record_.resize(hlen);
  src_.read(record_.data(), hlen);
  try {
    const Fields f = parse_fields(record_.data(), hlen);
    if (uint_field(f, "op", 1) != kBagHeader) throw std::runtime_error("the first record is not a Bag header (op 0x03)");
    index_pos_ = uint_field(f, "index_pos", 8);
    conn_count_ = static_cast<std::uint32_t>(uint_field(f, "conn_count", 4));
    chunk_count_ = static_cast<std::uint32_t>(uint_field(f, "chunk_count", 4));
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const InputError*>(&e)) throw;
    fail(at, std::string("Bag header: ") + e.what());
  }
  if (!src_.read(len4, 4)) fail(at, "the file ends inside the bag header");
  const std::uint64_t dlen = read_le(len4, 4);
  if (dlen > src_.left()) fail(at, "Bag header's padding runs past the end of the file");
  src_.skip(dlen);
  if (index_pos_ == 0)
    fail(at, "the bag has no index (index_pos 0: was the recorder stopped before it closed the file?); "
             "`rosbag reindex` it first");
  if (index_pos_ < src_.pos() || index_pos_ > src_.size())
    fail(at, "the index position " + std::to_string(index_pos_) + " is outside the data (" +
                 std::to_string(src_.pos()) + " .. " + std::to_string(src_.size()) + " bytes; truncated?)");
}

void Ros1BagReader::connection(const Record& r, std::uint64_t offset, bool in_chunk) {
  Ros1Connection c;
  c.id = static_cast<std::uint32_t>(uint_field(r.fields, "conn", 4));
  c.topic = string_field(r.fields, "topic");
  const Fields d = parse_fields(r.data, r.size);
  c.type = string_field(d, "type");
  c.md5sum = string_field(d, "md5sum");
  auto [it, fresh] = connections_.emplace(c.id, c);
  if (!fresh && (it->second.topic != c.topic || it->second.type != c.type || it->second.md5sum != c.md5sum)) {
    const std::string what = "connection " + std::to_string(c.id) + " is recorded again with another topic or type ('" +
                             c.topic + "' " + c.type + ", was '" + it->second.topic + "' " + it->second.type + ")";
    if (in_chunk) fail_in_chunk(offset, what);
    fail(offset, what);
  }
}

void Ros1BagReader::chunk(const Record& r, std::uint64_t offset) {
  const std::string compression = string_field(r.fields, "compression");
  const std::uint64_t size = uint_field(r.fields, "size", 4);
  if (size > max_chunk_)
    fail(offset, "Chunk declares " + std::to_string(size) + " uncompressed bytes, more than the " +
                     std::to_string(max_chunk_) + " this reader accepts");
  chunk_.resize(size);
  std::string err;
  if (compression == "none") {
    if (r.size != size) err = "holds " + std::to_string(r.size) + " bytes, declares " + std::to_string(size);
    else if (size) std::memcpy(chunk_.data(), r.data, size);
  } else if (compression == "lz4") {
    err = lz4_frame_decompress(r.data, r.size, chunk_.data(), size);
  } else if (compression == "bz2") {
    err = bz2_decompress(r.data, r.size, chunk_.data(), size);
  } else {
    fail(offset, "Chunk compression '" + compression + "' is not supported (expected none, bz2 or lz4)");
  }
  if (!err.empty()) fail(offset, compression + " Chunk does not decompress: " + err);
  chunk_pos_ = 0;
  chunk_offset_ = offset;
  in_chunk_ = true;
  chunk_messages_.clear();
  chunks_.push_back(ChunkIndex{offset, {}});
}

void Ros1BagReader::index_data(const Record& r, std::uint64_t offset) {
  if (chunks_.empty()) fail(offset, "Index data record before any chunk");
  if (uint_field(r.fields, "ver", 4) != 1) fail(offset, "Index data record of a version other than 1");
  const auto conn = static_cast<std::uint32_t>(uint_field(r.fields, "conn", 4));
  const std::uint64_t count = uint_field(r.fields, "count", 4);
  if (r.size != count * 12)
    fail(offset, "Index data record of " + std::to_string(count) + " entries holds " + std::to_string(r.size) +
                     " bytes, not " + std::to_string(count * 12));
  const auto& in_chunk = chunks_.back().messages;
  const auto n = in_chunk.find(conn);
  if (count != (n == in_chunk.end() ? 0 : n->second))
    fail(offset, "Index data record lists " + std::to_string(count) + " messages of connection " + std::to_string(conn) +
                     ", the chunk before it holds " + std::to_string(n == in_chunk.end() ? 0 : n->second));
  for (std::uint64_t k = 0; k < count; ++k) {
    const auto at = static_cast<std::uint32_t>(read_le(r.data + 12 * k + 8, 4));
    const auto m = chunk_messages_.find(at);
    if (m == chunk_messages_.end() || m->second != conn)
      fail(offset, "Index data record, entry " + std::to_string(k) + " (0-based): offset " + std::to_string(at) +
                       " is not a message of connection " + std::to_string(conn) + " in the chunk at byte " +
                       std::to_string(chunks_.back().offset) + " (" + std::to_string(chunk_.size()) +
                       " bytes uncompressed)");
  }
}

void Ros1BagReader::chunk_info(const Record& r, std::uint64_t offset) {
  if (uint_field(r.fields, "ver", 4) != 1) fail(offset, "Chunk info record of a version other than 1");
  const std::uint64_t chunk_pos = uint_field(r.fields, "chunk_pos", 8);
  const std::uint64_t count = uint_field(r.fields, "count", 4);
  if (r.size != count * 8)
    fail(offset, "Chunk info record of " + std::to_string(count) + " connections holds " + std::to_string(r.size) +
                     " bytes, not " + std::to_string(count * 8));
  if (chunk_infos_ >= chunks_.size() || chunks_[chunk_infos_].offset != chunk_pos)
    fail(offset, "Chunk info record for a chunk at byte " + std::to_string(chunk_pos) + ", where the data has " +
                     (chunk_infos_ < chunks_.size() ? "chunk " + std::to_string(chunk_infos_) + " at byte " +
                                                          std::to_string(chunks_[chunk_infos_].offset)
                                                    : std::string("no further chunk")));
  const auto& counts = chunks_[chunk_infos_].messages;
  if (count != counts.size())
    fail(offset, "Chunk info record lists " + std::to_string(count) + " connections, the chunk at byte " +
                     std::to_string(chunk_pos) + " holds " + std::to_string(counts.size()));
  for (std::uint64_t k = 0; k < count; ++k) {
    const auto conn = static_cast<std::uint32_t>(read_le(r.data + 8 * k, 4));
    const auto n = static_cast<std::uint32_t>(read_le(r.data + 8 * k + 4, 4));
    const auto it = counts.find(conn);
    if (it == counts.end() || it->second != n)
      fail(offset, "Chunk info record: connection " + std::to_string(conn) + " with " + std::to_string(n) +
                       " messages, the chunk at byte " + std::to_string(chunk_pos) + " holds " +
                       std::to_string(it == counts.end() ? 0 : it->second));
  }
  ++chunk_infos_;
}

void Ros1BagReader::finish_index() {
  if (chunks_.size() != chunk_count_ || chunk_infos_ != chunk_count_)
    fail(index_pos_, "the bag header declares " + std::to_string(chunk_count_) + " chunks; the data holds " +
                         std::to_string(chunks_.size()) + ", the index describes " + std::to_string(chunk_infos_));
  if (connections_.size() != conn_count_)
    fail(index_pos_, "the bag header declares " + std::to_string(conn_count_) + " connections; the bag holds " +
                         std::to_string(connections_.size()));
}

bool Ros1BagReader::next(Ros1Message& out) {
  for (;;) {
    if (in_chunk_) {
      // Inside a decompressed chunk: its records, then back to the file.
      if (chunk_pos_ == chunk_.size()) {
        in_chunk_ = false;
        continue;
      }
      const std::size_t at = chunk_pos_;
      Record r;
      try {
        const std::size_t left = chunk_.size() - at;
        if (left < 4) throw std::runtime_error("the chunk ends inside a record's header length");
        const std::uint64_t hlen = read_le(&chunk_[at], 4);
        if (hlen > left - 4) throw std::runtime_error("record header of " + std::to_string(hlen) + " bytes runs past the chunk's end");
        r.fields = parse_fields(&chunk_[at + 4], hlen);
        const std::size_t d = at + 4 + hlen;
        if (chunk_.size() - d < 4) throw std::runtime_error("the chunk ends inside a record's data length");
        const std::uint64_t dlen = read_le(&chunk_[d], 4);
        if (dlen > chunk_.size() - d - 4)
          throw std::runtime_error("record data of " + std::to_string(dlen) + " bytes runs past the chunk's end");
        r.op = static_cast<int>(uint_field(r.fields, "op", 1));
        r.data = &chunk_[d + 4];
        r.size = dlen;
        chunk_pos_ = d + 4 + dlen;
        if (r.op == kConnection) {
          connection(r, at, true);
          continue;
        }
        if (r.op != kMessageData)
          throw std::runtime_error(std::string("a chunk may hold only Connection and Message data records, not ") +
                                   op_name(r.op) + " (op " + std::to_string(r.op) + ")");
        out.conn = static_cast<std::uint32_t>(uint_field(r.fields, "conn", 4));
        const std::uint64_t time = uint_field(r.fields, "time", 8);
        if (!connections_.count(out.conn))
          throw std::runtime_error("Message data record of connection " + std::to_string(out.conn) +
                                   ", which has no Connection record before it");
        out.sec = static_cast<std::uint32_t>(time & 0xFFFFFFFFu);
        out.nsec = static_cast<std::uint32_t>(time >> 32);
        out.data = r.data;
        out.size = r.size;
        out.chunk_offset = chunk_offset_;
        out.offset = at;
        chunk_messages_[static_cast<std::uint32_t>(at)] = out.conn;
        ++chunks_.back().messages[out.conn];
        return true;
      } catch (const std::runtime_error& e) {
        if (dynamic_cast<const InputError*>(&e)) throw;
        fail_in_chunk(at, e.what());
      }
    }
    if (done_) return false;
    const std::uint64_t at = src_.pos();
    if (at == src_.size()) {
      finish_index();
      done_ = true;
      return false;
    }
    std::uint8_t len4[4];
    if (!src_.read(len4, 4)) fail(at, "the file ends inside a record's header length");
    const std::uint64_t hlen = read_le(len4, 4);
    if (hlen > kMaxHeader || hlen > src_.left())
      fail(at, "record header of " + std::to_string(hlen) + " bytes runs past the end of the file (" +
                   std::to_string(src_.left()) + " bytes left)");
    std::vector<std::uint8_t> head(hlen);
    src_.read(head.data(), hlen);
    Record r;
    try {
      r.fields = parse_fields(head.data(), hlen);
      r.op = static_cast<int>(uint_field(r.fields, "op", 1));
    } catch (const std::runtime_error& e) {
      fail(at, e.what());
    }
    if (!src_.read(len4, 4)) fail(at, std::string(op_name(r.op)) + " record: the file ends inside its data length");
    const std::uint64_t dlen = read_le(len4, 4);
    if (dlen > src_.left())
      fail(at, std::string(op_name(r.op)) + " record of " + std::to_string(dlen) +
                   " data bytes runs past the end of the file (" + std::to_string(src_.left()) + " bytes left)");
    if (dlen > max_chunk_ + (1u << 20))
      fail(at, std::string(op_name(r.op)) + " record of " + std::to_string(dlen) + " bytes is larger than this reader accepts");
    const bool index_section = at >= index_pos_;
    if (!index_section && src_.pos() + dlen > index_pos_)
      fail(at, std::string(op_name(r.op)) + " record runs past the index position " + std::to_string(index_pos_));
    record_.resize(dlen);
    src_.read(record_.data(), dlen);
    r.data = record_.data();
    r.size = dlen;
    try {
      switch (r.op) {
        case kChunk:
          if (index_section) fail(at, "Chunk record in the index section");
          chunk(r, at);
          continue;
        case kIndexData:
          if (index_section) fail(at, "Index data record in the index section");
          index_data(r, at);
          continue;
        case kConnection:
          connection(r, at, false);
          continue;
        case kChunkInfo:
          if (!index_section) fail(at, "Chunk info record before the index position " + std::to_string(index_pos_));
          chunk_info(r, at);
          continue;
        case kBagHeader:
          fail(at, "a second Bag header record");
        default:
          fail(at, std::string("unexpected ") + op_name(r.op) + " (op " + std::to_string(r.op) +
                       ") outside a chunk");
      }
    } catch (const std::runtime_error& e) {
      if (dynamic_cast<const InputError*>(&e)) throw;
      fail(at, std::string(op_name(r.op)) + " record: " + e.what());
    }
  }
}

namespace {

/// The MD5 sums of the message definitions this reader decodes (those of the ROS 1
/// message packages; a connection with another sum was recorded with another definition).
const char* known_md5(MessageKind kind) {
  switch (kind) {
    case MessageKind::kImu: return "6a62c6daae103f4ff57a132d6f95cec2";
    case MessageKind::kOdometry: return "cd5e73d190d741a2f92e81eda573aca7";
    case MessageKind::kPoseStamped: return "d3812c3cbc69362b77dc0b19b345f8f5";
    case MessageKind::kTf: return "94810edda583a504dfda3829e70d7eec";
    case MessageKind::kOther: break;
  }
  return "";
}

/// ROS 1 bag: the file is read once for its connections and message counts (checking the
/// whole structure and index), then again for the messages.
class Ros1Bag final : public RecordingReader {
 public:
  explicit Ros1Bag(const fs::path& file) : file_(file) {
    Ros1BagReader r(file);
    Ros1Message m;
    std::map<std::uint32_t, std::uint64_t> per_conn;
    while (r.next(m)) ++per_conn[m.conn];
    std::map<std::string, std::size_t> by_name;
    for (const auto& [id, c] : r.connections()) {
      auto [it, fresh] = by_name.emplace(c.topic, topics_.size());
      if (fresh) {
        TopicInfo t;
        t.name = c.topic;
        t.type = c.type;
        t.kind = message_kind(c.type);
        topics_.push_back(t);
      } else if (topics_[it->second].type != c.type) {
        throw InputError(r.name() + ": topic '" + c.topic + "' is recorded with two types, '" +
                         topics_[it->second].type + "' and '" + c.type + "'");
      }
      topics_[it->second].count += per_conn[id];
      topic_of_[id] = it->second;
      if (topics_[it->second].kind != MessageKind::kOther && c.md5sum != known_md5(topics_[it->second].kind))
        wrong_md5_[it->second] = c.md5sum;
    }
    counts_.assign(topics_.size(), 0);
    wanted_.assign(topics_.size(), true);
  }

  const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::string format() const override { return "ROS 1 bag"; }

  void select(const std::vector<bool>& wanted) override {
    wanted_ = wanted;
    for (std::size_t i = 0; i < topics_.size(); ++i)
      if (wanted_[i] && wrong_md5_.count(i))
        throw InputError(where() + ": topic '" + topics_[i].name + "': message type '" + topics_[i].type + "' (MD5 " +
                         wrong_md5_.at(i) + ") is not the " + topics_[i].type + " definition this build knows (MD5 " +
                         known_md5(topics_[i].kind) + ")");
  }

  bool next(Message& out) override {
    if (!reader_) {
      select(wanted_);
      reader_ = std::make_unique<Ros1BagReader>(file_);
    }
    Ros1Message m;
    for (;;) {
      if (!reader_->next(m)) return false;
      const std::size_t t = topic_of_.at(m.conn);
      if (!wanted_[t]) continue;
      out.topic = t;
      out.index = counts_[t]++;
      out.receive_ns = Stamp{m.sec, m.nsec}.ns();
      if (topics_[t].kind == MessageKind::kOther)
        throw InputError(where() + ": topic '" + topics_[t].name + "' has type '" + topics_[t].type +
                         "', which wheelins cannot read");
      try {
        decode_ros1(topics_[t].kind, m.data, m.size, out);
      } catch (const CdrError& e) {
        throw InputError(where() + ": topic '" + topics_[t].name + "', message " + std::to_string(out.index) +
                         " (0-based; chunk at byte " + std::to_string(m.chunk_offset) + ", record at byte " +
                         std::to_string(m.offset) + " of its data): cannot read: " + e.what());
      }
      return true;
    }
  }

 private:
  std::string where() const { return "'" + file_.string() + "'"; }

  fs::path file_;
  std::vector<TopicInfo> topics_;
  std::map<std::uint32_t, std::size_t> topic_of_;
  std::map<std::size_t, std::string> wrong_md5_;
  std::vector<std::uint64_t> counts_;
  std::vector<bool> wanted_;
  std::unique_ptr<Ros1BagReader> reader_;
};

}  // namespace

std::unique_ptr<RecordingReader> open_ros1_bag(const fs::path& file) { return std::make_unique<Ros1Bag>(file); }

}  // namespace wheelins::ros
