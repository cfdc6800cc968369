// LZ4 frame and bzip2 decompression into a buffer of the declared size (decompress.hpp).
#include "wheelins/io/ros/decompress.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <climits>

namespace wheelins::ros {

std::string lz4_frame_decompress(const std::uint8_t* src, std::size_t n, std::uint8_t* dst, std::size_t size) {
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) return "out of memory";
  std::size_t in_pos = 0, out_pos = 0;
  std::size_t hint = 1;
  std::string err;
  while (hint != 0 && in_pos < n) {
    std::size_t got = size - out_pos, used = n - in_pos;
    hint = LZ4F_decompress(ctx, dst + out_pos, &got, src + in_pos, &used, nullptr);
    if (LZ4F_isError(hint)) {
      err = LZ4F_getErrorName(hint);
      break;
    }
    in_pos += used;
    out_pos += got;
    if (got == 0 && used == 0) {
      err = "no progress (the frame is longer than the declared size)";
      break;
    }
  }
  LZ4F_freeDecompressionContext(ctx);
  if (!err.empty()) return err;
  if (hint != 0) return "the data ends inside its frame (truncated?)";
  if (out_pos != size)
    return "gives " + std::to_string(out_pos) + " bytes, declares " + std::to_string(size);
  return {};
}

std::string bz2_decompress(const std::uint8_t* src, std::size_t n, std::uint8_t* dst, std::size_t size) {
  if (n > UINT_MAX || size > UINT_MAX) return "more than 4 GiB in one stream";
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) return "out of memory";
  s.next_in = const_cast<char*>(reinterpret_cast<const char*>(src));
  s.avail_in = static_cast<unsigned>(n);
  s.next_out = reinterpret_cast<char*>(dst);
  s.avail_out = static_cast<unsigned>(size);
  int rc = BZ_OK;
  while (rc == BZ_OK) {
    const unsigned in_before = s.avail_in, out_before = s.avail_out;
    rc = BZ2_bzDecompress(&s);
    if (rc == BZ_OK && s.avail_in == in_before && s.avail_out == out_before) break;  // no progress
  }
  const std::size_t got = size - s.avail_out;
  BZ2_bzDecompressEnd(&s);
  if (rc == BZ_STREAM_END) {
    if (got != size) return "gives " + std::to_string(got) + " bytes, declares " + std::to_string(size);
    return {};
  }
  if (rc == BZ_OK) return s.avail_out == 0 ? "longer than the declared " + std::to_string(size) + " bytes"
                                            : "the data ends inside the stream (truncated?)";
  if (rc == BZ_DATA_ERROR || rc == BZ_DATA_ERROR_MAGIC) return "not bzip2 data, or corrupt";
  if (rc == BZ_MEM_ERROR) return "out of memory";
  return "bzip2 error " + std::to_string(rc);
}

}  // namespace wheelins::ros
