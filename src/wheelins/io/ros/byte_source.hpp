// The bytes of a recording file, or of a buffer in memory (the fuzzers'), read front to
// back with the offset of the next byte: what the MCAP and ROS 1 bag readers share.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace wheelins::ros {

/// Little-endian unsigned integer of n bytes at p.
inline std::uint64_t read_le(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= std::uint64_t(p[i]) << (8 * i);
  return v;
}

class ByteSource {
 public:
  /// Opens `file`; InputError naming it when it is a directory ("expected <expected>"),
  /// cannot be opened or its size cannot be read.
  ByteSource(const std::filesystem::path& file, const std::string& expected);
  /// Bytes held in memory (they must outlive the source); `name` is used in messages.
  ByteSource(std::string name, const std::uint8_t* data, std::size_t size);
  ~ByteSource();
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;

  /// Fills `out` with the next n bytes; false (nothing read) when fewer are left.
  bool read(std::uint8_t* out, std::size_t n);
  /// Moves on n bytes (n <= left()).
  void skip(std::uint64_t n);
  std::uint64_t pos() const { return pos_; }
  std::uint64_t size() const { return size_; }
  std::uint64_t left() const { return size_ - pos_; }
  const std::string& name() const { return name_; }  ///< quoted file name
  /// InputError "<name>: byte <offset>: <what>".
  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const;

 private:
  std::string name_;
  std::FILE* fp_ = nullptr;
  const std::uint8_t* mem_ = nullptr;
  std::uint64_t size_ = 0, pos_ = 0;
};

}  // namespace wheelins::ros
