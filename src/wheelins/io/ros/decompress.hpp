// Whole-buffer decompression for the recording readers: an LZ4 frame (MCAP chunks,
// ROS 1 bag chunks, whose roslz4 streams are LZ4 frames) and a bzip2 stream (ROS 1 bag
// chunks). The output size is declared by the container and checked: a stream that
// gives more or fewer bytes is an error, never a write past `dst`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace wheelins::ros {

/// Decompresses `n` bytes at `src` into exactly `size` bytes at `dst`. Returns an empty
/// string on success, otherwise what went wrong (for the caller's error message).
std::string lz4_frame_decompress(const std::uint8_t* src, std::size_t n, std::uint8_t* dst, std::size_t size);
std::string bz2_decompress(const std::uint8_t* src, std::size_t n, std::uint8_t* dst, std::size_t size);

}  // namespace wheelins::ros
