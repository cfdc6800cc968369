// A recording's bytes from a file or from memory (byte_source.hpp).
#include "wheelins/io/ros/byte_source.hpp"

#include <cerrno>
#include <cstring>

#include "wheelins/nav/types.hpp"

namespace wheelins::ros {
namespace fs = std::filesystem;

ByteSource::ByteSource(const fs::path& file, const std::string& expected) : name_("'" + file.string() + "'") {
  std::error_code ec;
  if (fs::is_directory(file, ec)) throw InputError(name_ + ": is a directory, expected " + expected);
  fp_ = std::fopen(file.c_str(), "rb");
  if (!fp_) throw InputError(name_ + ": cannot open: " + std::strerror(errno));
  const auto size = fs::file_size(file, ec);
  if (ec) {
    std::fclose(fp_);
    throw InputError(name_ + ": cannot read its size: " + ec.message());
  }
  size_ = size;
}

ByteSource::ByteSource(std::string name, const std::uint8_t* data, std::size_t size)
    : name_(std::move(name)), mem_(data), size_(size) {}

ByteSource::~ByteSource() {
  if (fp_) std::fclose(fp_);
}

void ByteSource::fail(std::uint64_t offset, const std::string& what) const {
  throw InputError(name_ + ": byte " + std::to_string(offset) + ": " + what);
}

bool ByteSource::read(std::uint8_t* out, std::size_t n) {
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

void ByteSource::skip(std::uint64_t n) {
  if (fp_ && std::fseek(fp_, static_cast<long>(pos_ + n), SEEK_SET) != 0) fail(pos_, "seek error");
  pos_ += n;
}

}  // namespace wheelins::ros
