// The MCAP reader (mcap.hpp): records read linearly, chunks decompressed (zstd, lz4) and
// checked by their CRC-32, a truncated file reported with the record's offset.
#include "wheelins/io/ros/mcap.hpp"

#include <zstd.h>

#include <array>
#include <cstring>
#include <stdexcept>

#include "wheelins/io/ros/decompress.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::ros {
namespace fs = std::filesystem;

namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
enum Op : std::uint8_t {
  kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05,
  kChunk = 0x06, kDataEnd = 0x0F
};
constexpr std::size_t kRecordHead = 9;  // opcode + uint64 length

const char* op_name(std::uint8_t op) {
  switch (op) {
    case kHeader: return "Header";
    case kFooter: return "Footer";
    case kSchema: return "Schema";
    case kChannel: return "Channel";
    case kMessage: return "Message";
    case kChunk: return "Chunk";
    case kDataEnd: return "DataEnd";
    default: return "record";
  }
}

/// Bounds-checked little-endian fields of one record's content.
struct Cursor {
  const std::uint8_t* p;
  std::size_t n, pos = 0;
  const char* record;
  const std::uint8_t* take(std::size_t k, const char* field) {
    if (k > n - pos)
      throw std::runtime_error(std::string(record) + " record: field " + field + " (" + std::to_string(k) +
                               " bytes) runs past the record's end (" + std::to_string(n - pos) + " left)");
    const std::uint8_t* r = p + pos;
    pos += k;
    return r;
  }
  std::uint16_t u16(const char* f) { return static_cast<std::uint16_t>(read_le(take(2, f), 2)); }
  std::uint32_t u32(const char* f) { return static_cast<std::uint32_t>(read_le(take(4, f), 4)); }
  std::uint64_t u64(const char* f) { return read_le(take(8, f), 8); }
  std::string str(const char* f) {
    const std::uint32_t k = u32(f);
    const std::uint8_t* s = take(k, f);
    return std::string(reinterpret_cast<const char*>(s), k);
  }
};

std::array<std::uint32_t, 256> crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}

}  // namespace

std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc) {
  static const std::array<std::uint32_t, 256> table = crc_table();
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

McapReader::McapReader(const fs::path& file, std::uint64_t max_chunk_bytes)
    : src_(file, "an .mcap file"), max_chunk_(max_chunk_bytes) {
  start();
}

McapReader::McapReader(std::string name, const std::uint8_t* data, std::size_t size,
                       std::uint64_t max_chunk_bytes)
    : src_(std::move(name), data, size), max_chunk_(max_chunk_bytes) {
  start();
}

void McapReader::start() {
  std::uint8_t magic[8];
  if (!src_.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0)
    fail(0, "not an MCAP file (no magic \\x89MCAP0\\r\\n at the start)");
  std::uint8_t head[kRecordHead];
  const std::uint64_t at = src_.pos();
  if (!src_.read(head, kRecordHead) || head[0] != kHeader)
    fail(at, "the first record is not a Header record (opcode 0x01)");
  const std::uint64_t len = read_le(head + 1, 8);
  if (len > src_.left()) fail(at, "Header record of " + std::to_string(len) + " bytes runs past the end of the file");
  record_.resize(len);
  src_.read(record_.data(), len);
  McapMessage unused;
  record(kHeader, record_.data(), len, at, false, unused);
}

bool McapReader::record(std::uint8_t op, const std::uint8_t* p, std::size_t n, std::uint64_t offset,
                        bool in_chunk, McapMessage& out) {
  Cursor c{p, n, 0, op_name(op)};
  try {
    switch (op) {
      case kHeader:
        profile_ = c.str("profile");
        c.str("library");
        return false;
      case kSchema: {
        McapSchema s;
        s.id = c.u16("id");
        s.name = c.str("name");
        s.encoding = c.str("encoding");
        const std::uint32_t k = c.u32("data");
        c.take(k, "data");
        if (s.id == 0) throw std::runtime_error("Schema record: id 0 is reserved");
        schemas_[s.id] = s;
        return false;
      }
      case kChannel: {
        McapChannel ch;
        ch.id = c.u16("id");
        ch.schema_id = c.u16("schema_id");
        ch.topic = c.str("topic");
        ch.message_encoding = c.str("message_encoding");
        const std::uint32_t k = c.u32("metadata");
        c.take(k, "metadata");
        channels_[ch.id] = ch;
        return false;
      }
      case kMessage:
        out.channel = c.u16("channel_id");
        c.u32("sequence");
        out.log_time = c.u64("log_time");
        out.publish_time = c.u64("publish_time");
        out.data = p + c.pos;
        out.size = n - c.pos;
        out.offset = offset;
        if (!channels_.count(out.channel))
          throw std::runtime_error("Message record: channel " + std::to_string(out.channel) +
                                   " has no Channel record before it");
        return true;
      case kChunk:
        if (in_chunk) throw std::runtime_error("Chunk record inside a chunk");
        chunk(p, n, offset);
        return false;
      default:
        return false;  // index, attachment, metadata, statistics ... records: not needed
    }
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const InputError*>(&e)) throw;
    fail(offset, e.what());
  }
}

void McapReader::chunk(const std::uint8_t* p, std::size_t n, std::uint64_t offset) {
  Cursor c{p, n, 0, "Chunk"};
  c.u64("message_start_time");
  c.u64("message_end_time");
  const std::uint64_t size = c.u64("uncompressed_size");
  const std::uint32_t crc = c.u32("uncompressed_crc");
  const std::string compression = c.str("compression");
  const std::uint64_t k = c.u64("records (length)");
  const std::uint8_t* src = c.take(k, "records");
  if (size > max_chunk_)
    fail(offset, "Chunk declares " + std::to_string(size) + " uncompressed bytes, more than the " +
                     std::to_string(max_chunk_) + " this reader accepts");
  chunk_.resize(size);
  if (compression.empty()) {
    if (k != size) fail(offset, "uncompressed Chunk holds " + std::to_string(k) + " bytes, declares " + std::to_string(size));
    if (size) std::memcpy(chunk_.data(), src, size);
  } else if (compression == "zstd") {
    const std::size_t got = ZSTD_decompress(chunk_.data(), size, src, k);
    if (ZSTD_isError(got)) fail(offset, std::string("zstd Chunk does not decompress: ") + ZSTD_getErrorName(got));
    if (got != size) fail(offset, "zstd Chunk gives " + std::to_string(got) + " bytes, declares " + std::to_string(size));
  } else if (compression == "lz4") {
    const std::string err = lz4_frame_decompress(src, k, chunk_.data(), size);
    if (!err.empty()) fail(offset, "lz4 Chunk does not decompress: " + err);
  } else {
    fail(offset, "Chunk compression '" + compression + "' is not supported (expected none, zstd or lz4)");
  }
  if (crc != 0 && crc32(chunk_.data(), chunk_.size()) != crc)
    fail(offset, "Chunk CRC-32 does not match its content (corrupt file?)");
  chunk_pos_ = 0;
  chunk_offset_ = offset;
  in_chunk_ = true;
}

bool McapReader::next(McapMessage& out) {
  for (;;) {
    if (in_chunk_) {
      // Inside a decompressed chunk: its records, then back to the file.
      if (chunk_pos_ == chunk_.size()) {
        in_chunk_ = false;
        continue;
      }
      if (chunk_.size() - chunk_pos_ < kRecordHead)
        fail(chunk_offset_, "Chunk ends inside a record header (byte " + std::to_string(chunk_pos_) +
                                " of its records)");
      const std::uint8_t op = chunk_[chunk_pos_];
      const std::uint64_t len = read_le(&chunk_[chunk_pos_ + 1], 8);
      const std::size_t body = chunk_pos_ + kRecordHead;
      if (len > chunk_.size() - body)
        fail(chunk_offset_, std::string(op_name(op)) + " record at byte " + std::to_string(chunk_pos_) +
                                " of the chunk runs past the chunk's end");
      chunk_pos_ = body + len;
      if (op != kSchema && op != kChannel && op != kMessage)
        fail(chunk_offset_, std::string("a chunk may hold only Schema, Channel and Message records, not ") +
                                "opcode " + std::to_string(op));
      if (record(op, &chunk_[body], len, chunk_offset_, true, out)) return true;
      continue;
    }
    if (done_) return false;
    const std::uint64_t at = src_.pos();
    std::uint8_t head[kRecordHead];
    if (!src_.read(head, kRecordHead)) {
      if (src_.left() == 0)
        fail(at, "the file ends without a DataEnd or Footer record (truncated: was the recorder "
                 "stopped before it closed the file?)");
      fail(at, "the file ends inside a record header (truncated?)");
    }
    const std::uint8_t op = head[0];
    const std::uint64_t len = read_le(head + 1, 8);
    if (len > src_.left())
      fail(at, std::string(op_name(op)) + " record of " + std::to_string(len) + " bytes runs past the end of the file (" +
                   std::to_string(src_.left()) + " bytes left; truncated?)");
    if (op == kDataEnd || op == kFooter) {
      done_ = true;  // the summary that may follow repeats what the data section had
      return false;
    }
    if (op != kSchema && op != kChannel && op != kMessage && op != kChunk) {
      src_.skip(len);  // attachments, metadata, index records: not needed
      continue;
    }
    if (op == kChunk && len > max_chunk_ + (1u << 20))
      fail(at, "Chunk record of " + std::to_string(len) + " bytes is larger than this reader accepts");
    record_.resize(len);
    src_.read(record_.data(), len);
    if (record(op, record_.data(), len, at, false, out)) return true;
  }
}

}  // namespace wheelins::ros
