// A bounds-checked reader of ROS 1 bag files (format 2.0,
// http://wiki.ros.org/Bags/Format/2.0), of our own: the ROS bag storage library trusts
// the file's offsets (an index entry pointing past its chunk made it read out of bounds
// and crash), so nothing of it is used to read.
//
// File:    "#ROSBAG V2.0\n", then records to the end of the file.
// Record:  uint32 header length, header, uint32 data length, data. Little-endian integers.
// Header:  fields, each uint32 length + "name=value" (the value binary); "op" (1 byte) is
//          the record's kind:
//   0x03 Bag header  index_pos uint64 (where the index section starts), conn_count uint32,
//                    chunk_count uint32; data: padding. The first record.
//   0x05 Chunk       compression ("none", "bz2", "lz4": a bzip2 stream or an LZ4 frame),
//                    size uint32 (uncompressed); data: Connection and Message data records
//   0x04 Index data  ver uint32 (1), conn uint32, count uint32; data: count x (time uint64,
//                    offset uint32: of a Message data record in the chunk before it)
//   0x07 Connection  conn uint32, topic string; data: a header (topic, type, md5sum,
//                    message_definition, ...)
//   0x02 Message data conn uint32, time uint64 (uint32 sec, uint32 nsec: the receive time);
//                    data: the message in the ROS 1 serialisation (cdr.hpp, decode_ros1)
//   0x06 Chunk info  ver uint32 (1), chunk_pos uint64, start_time, end_time uint64,
//                    count uint32; data: count x (conn uint32, count uint32)
// The data section (chunks, each followed by its index data records) runs to index_pos;
// the index section (Connection and Chunk info records) from there to the end of the file.
// The records are read in file order. Every length and offset is checked against what
// holds it (the file, the record, the chunk); the index is checked against the chunks
// (each index entry names a Message data record of its connection at its offset, each
// chunk info a chunk that is there, the counts the header declares). A bag without an
// index (index_pos 0: the recorder was stopped before it closed the file) is an error, as
// the file's end cannot then be told from a truncation.
// Errors throw InputError naming the file, the byte offset of the record and, inside a
// chunk, the byte offset in the chunk's uncompressed data.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "wheelins/io/ros/byte_source.hpp"

namespace wheelins::ros {

struct Ros1Connection {
  std::uint32_t id = 0;
  std::string topic, type, md5sum;
};

/// A message as stored; data points into the reader's buffer (valid until next()).
struct Ros1Message {
  std::uint32_t conn = 0;
  std::uint32_t sec = 0, nsec = 0;  ///< the record's time (the recorder's receive time)
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::uint64_t chunk_offset = 0;  ///< file offset of its chunk record (0: not in a chunk)
  std::uint64_t offset = 0;        ///< offset in the chunk's data (file offset when not in a chunk)
};

class Ros1BagReader {
 public:
  /// Reads `file`. `max_chunk_bytes` bounds a chunk's uncompressed size (a larger declared
  /// size is an error, never an allocation).
  explicit Ros1BagReader(const std::filesystem::path& file, std::uint64_t max_chunk_bytes = 1ull << 30);
  /// Reads a file held in memory (the bytes must outlive the reader); `name` is used in messages.
  Ros1BagReader(std::string name, const std::uint8_t* data, std::size_t size,
                std::uint64_t max_chunk_bytes = 1ull << 30);
  Ros1BagReader(const Ros1BagReader&) = delete;
  Ros1BagReader& operator=(const Ros1BagReader&) = delete;

  /// The next Message data record; false at the end of the file (after the index has
  /// been read and checked).
  bool next(Ros1Message& out);

  /// The connections met so far (all of them once next() has returned false).
  const std::map<std::uint32_t, Ros1Connection>& connections() const { return connections_; }
  const std::string& name() const { return src_.name(); }

  /// A record header's fields: name -> value bytes (pointing into the header).
  struct Field {
    const std::uint8_t* p = nullptr;
    std::size_t n = 0;
  };

 private:
  struct Record;
  struct ChunkIndex {  // what the data section said of one chunk, to check the index against
    std::uint64_t offset = 0;
    std::map<std::uint32_t, std::uint32_t> messages;  // per connection
  };
  void start();
  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const;
  [[noreturn]] void fail_in_chunk(std::uint64_t at, const std::string& what) const;
  void chunk(const Record& r, std::uint64_t offset);
  void index_data(const Record& r, std::uint64_t offset);
  void chunk_info(const Record& r, std::uint64_t offset);
  void connection(const Record& r, std::uint64_t offset, bool in_chunk);
  void finish_index();

  ByteSource src_;
  std::uint64_t max_chunk_;
  std::uint64_t index_pos_ = 0;
  std::uint32_t conn_count_ = 0, chunk_count_ = 0;
  std::vector<std::uint8_t> record_, chunk_;
  std::size_t chunk_pos_ = 0;
  std::uint64_t chunk_offset_ = 0;
  bool in_chunk_ = false, done_ = false;
  // The last chunk's Message data records by offset (for its index data records).
  std::map<std::uint32_t, std::uint32_t> chunk_messages_;  // offset -> connection
  std::vector<ChunkIndex> chunks_;
  std::size_t chunk_infos_ = 0;
  std::map<std::uint32_t, Ros1Connection> connections_;
};

}  // namespace wheelins::ros
