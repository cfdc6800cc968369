// A small reader of MCAP files (https://mcap.dev/spec, format version 0), the
// default ROS 2 bag storage since Iron. It reads the data section linearly; the
// optional summary and index records are skipped. A file that ends without a
// DataEnd or Footer record is reported as truncated.
//
// File:    magic "\x89MCAP0\r\n", records, magic.
// Record:  opcode (uint8), content length (uint64), content. Little-endian integers;
//          String = uint32 byte length + UTF-8; Bytes = uint32 length + bytes;
//          Map<String,String> = uint32 byte length + key/value pairs.
// Used records (others are skipped by their length, as the spec requires of unknown ones):
//   0x01 Header   profile String, library String
//   0x03 Schema   id uint16, name String, encoding String, data Bytes
//   0x04 Channel  id uint16, schema_id uint16, topic String, message_encoding String,
//                 metadata Map<String,String>
//   0x05 Message  channel_id uint16, sequence uint32, log_time uint64, publish_time uint64,
//                 data (the rest of the record)
//   0x06 Chunk    message_start_time uint64, message_end_time uint64, uncompressed_size
//                 uint64, uncompressed_crc uint32 (CRC-32, 0 = not given), compression String
//                 ("", "zstd", "lz4": a Zstandard frame or an LZ4 frame), records uint64
//                 length + bytes: Schema, Channel and Message records as above
//   0x0F DataEnd  ends the data section (then summary, footer, magic)
// Errors throw InputError naming the file and the byte offset of the record.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/io/ros/byte_source.hpp"

namespace wheelins::ros {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name, encoding;
};

struct McapChannel {
  std::uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
};

/// A message as stored; data points into the reader's buffer (valid until next()).
struct McapMessage {
  std::uint16_t channel = 0;
  std::uint64_t log_time = 0, publish_time = 0;
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::uint64_t offset = 0;  ///< file offset of the record (of its chunk, inside one)
};

class McapReader {
 public:
  /// Reads `file`. `max_chunk_bytes` bounds the uncompressed size of a chunk (a larger
  /// declared size is an error, never an allocation).
  explicit McapReader(const std::filesystem::path& file, std::uint64_t max_chunk_bytes = 1ull << 30);
  /// Reads a file held in memory (the bytes must outlive the reader); `name` is used in messages.
  McapReader(std::string name, const std::uint8_t* data, std::size_t size,
             std::uint64_t max_chunk_bytes = 1ull << 30);
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  /// The next message record; false at the end of the data section.
  bool next(McapMessage& out);

  const std::map<std::uint16_t, McapSchema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, McapChannel>& channels() const { return channels_; }
  const std::string& profile() const { return profile_; }
  const std::string& name() const { return src_.name(); }

 private:
  void start();
  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const { src_.fail(offset, what); }
  /// Handles one record; true if it was a message (then `out` is set).
  bool record(std::uint8_t op, const std::uint8_t* p, std::size_t n, std::uint64_t offset,
              bool in_chunk, McapMessage& out);
  void chunk(const std::uint8_t* p, std::size_t n, std::uint64_t offset);

  ByteSource src_;
  std::uint64_t max_chunk_;
  std::vector<std::uint8_t> record_, chunk_;
  std::size_t chunk_pos_ = 0;
  std::uint64_t chunk_offset_ = 0;
  bool in_chunk_ = false, done_ = false;
  std::string profile_;
  std::map<std::uint16_t, McapSchema> schemas_;
  std::map<std::uint16_t, McapChannel> channels_;
};

/// CRC-32 (IEEE 802.3, reflected, as zlib's crc32), what MCAP's CRC fields hold.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace wheelins::ros
