// The MCAP reader (mcap.hpp): records read linearly, chunks decompressed (zstd, lz4) and
// checked by their CRC-32, a truncated file reported with the record's offset.
#include "wheelins/io/ros/mcap.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <array>
#include <cstring>
#include <stdexcept>

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

std::uint64_t le(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= std::uint64_t(p[i]) << (8 * i);
  return v;
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
  std::uint16_t u16(const char* f) { return static_cast<std::uint16_t>(le(take(2, f), 2)); }
  std::uint32_t u32(const char* f) { return static_cast<std::uint32_t>(le(take(4, f), 4)); }
  std::uint64_t u64(const char* f) { return le(take(8, f), 8); }
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
    : name_("'" + file.string() + "'"), max_chunk_(max_chunk_bytes) {
  std::error_code ec;
  if (fs::is_directory(file, ec)) throw InputError(name_ + ": is a directory, expected an .mcap file");
  fp_ = std::fopen(file.c_str(), "rb");
  if (!fp_) throw InputError(name_ + ": cannot open: " + std::strerror(errno));
  const auto size = fs::file_size(file, ec);
  if (ec) throw InputError(name_ + ": cannot read its size: " + ec.message());
  size_ = size;
  start();
}

McapReader::McapReader(std::string name, const std::uint8_t* data, std::size_t size,
                       std::uint64_t max_chunk_bytes)
    : name_(std::move(name)), mem_(data), size_(size), max_chunk_(max_chunk_bytes) {
  start();
}

McapReader::~McapReader() {
  if (fp_) std::fclose(fp_);
}

void McapReader::fail(std::uint64_t offset, const std::string& what) const {
  throw InputError(name_ + ": byte " + std::to_string(offset) + ": " + what);
}

bool McapReader::read_bytes(std::uint8_t* out, std::size_t n) {
  if (n > size_ - pos_) return false;
  if (n == 0) return true;  // (an empty record: out may be null)
  if (mem_) {
    std::memcpy(out, mem_ + pos_, n);
  } else if (std::fread(out, 1, n, fp_) != n) {
    fail(pos_, "read error");
  }
  pos_ += n;
  return true;
}

void McapReader::skip(std::uint64_t n) {
  if (fp_ && std::fseek(fp_, static_cast<long>(pos_ + n), SEEK_SET) != 0) fail(pos_, "seek error");
  pos_ += n;
}

void McapReader::start() {
  std::uint8_t magic[8];
  if (!read_bytes(magic, 8) || std::memcmp(magic, kMagic, 8) != 0)
    fail(0, "not an MCAP file (no magic \\x89MCAP0\\r\\n at the start)");
  std::uint8_t head[kRecordHead];
  const std::uint64_t at = pos_;
  if (!read_bytes(head, kRecordHead) || head[0] != kHeader)
    fail(at, "the first record is not a Header record (opcode 0x01)");
  const std::uint64_t len = le(head + 1, 8);
  if (len > size_ - pos_) fail(at, "Header record of " + std::to_string(len) + " bytes runs past the end of the file");
  record_.resize(len);
  read_bytes(record_.data(), len);
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
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) fail(offset, "lz4: out of memory");
    std::size_t in_pos = 0, out_pos = 0;
    std::size_t hint = 1;
    std::string err;
    while (hint != 0 && in_pos < k) {
      std::size_t dst = size - out_pos, srcn = k - in_pos;
      hint = LZ4F_decompress(ctx, chunk_.data() + out_pos, &dst, src + in_pos, &srcn, nullptr);
      if (LZ4F_isError(hint)) {
        err = LZ4F_getErrorName(hint);
        break;
      }
      in_pos += srcn;
      out_pos += dst;
      if (dst == 0 && srcn == 0) {
        err = "no progress (the frame is longer than the declared size)";
        break;
      }
    }
    LZ4F_freeDecompressionContext(ctx);
    if (!err.empty()) fail(offset, "lz4 Chunk does not decompress: " + err);
    if (hint != 0) fail(offset, "lz4 Chunk ends inside its frame (truncated?)");
    if (out_pos != size)
      fail(offset, "lz4 Chunk gives " + std::to_string(out_pos) + " bytes, declares " + std::to_string(size));
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
      const std::uint64_t len = le(&chunk_[chunk_pos_ + 1], 8);
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
    const std::uint64_t at = pos_;
    std::uint8_t head[kRecordHead];
    if (!read_bytes(head, kRecordHead)) {
      if (size_ - pos_ == 0)
        fail(at, "the file ends without a DataEnd or Footer record (truncated: was the recorder "
                 "stopped before it closed the file?)");
      fail(at, "the file ends inside a record header (truncated?)");
    }
    const std::uint8_t op = head[0];
    const std::uint64_t len = le(head + 1, 8);
    if (len > size_ - pos_)
      fail(at, std::string(op_name(op)) + " record of " + std::to_string(len) + " bytes runs past the end of the file (" +
                   std::to_string(size_ - pos_) + " bytes left; truncated?)");
    if (op == kDataEnd || op == kFooter) {
      done_ = true;  // the summary that may follow repeats what the data section had
      return false;
    }
    if (op != kSchema && op != kChannel && op != kMessage && op != kChunk) {
      skip(len);  // attachments, metadata, index records: not needed
      continue;
    }
    if (op == kChunk && len > max_chunk_ + (1u << 20))
      fail(at, "Chunk record of " + std::to_string(len) + " bytes is larger than this reader accepts");
    record_.resize(len);
    read_bytes(record_.data(), len);
    if (record(op, record_.data(), len, at, false, out)) return true;
  }
}

}  // namespace wheelins::ros
