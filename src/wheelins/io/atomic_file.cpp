#include "wheelins/io/atomic_file.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <system_error>

#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace {
constexpr std::size_t kFlushBytes = 1 << 20;

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }
}  // namespace

void check_output_target(const std::filesystem::path& file, bool overwrite) {
  std::error_code ec;
  const auto st = std::filesystem::status(file, ec);
  if (std::filesystem::is_directory(st))
    throw InputError(quote(file) + ": is a directory, expected an output file name");
  if (std::filesystem::exists(st) && !overwrite)
    throw InputError(quote(file) + ": already exists; refusing to overwrite it (ask for overwrite, "
                     "e.g. --force, or choose another name)");
}

void append_double(std::string& out, double value, int significant) {
  if (std::isnan(value)) {
    out += "nan";
    return;
  }
  char buf[64];
  const auto res = significant > 0
                       ? std::to_chars(buf, buf + sizeof(buf), value,
                                       std::chars_format::general, significant)
                       : std::to_chars(buf, buf + sizeof(buf), value);
  out.append(buf, res.ptr);
}

void append_fixed(std::string& out, double value, int decimals) {
  if (std::isnan(value)) {
    out += "nan";
    return;
  }
  char buf[400];  // fixed notation of a large double needs ~310 digits
  const auto res =
      std::to_chars(buf, buf + sizeof(buf), value, std::chars_format::fixed, decimals);
  out.append(buf, res.ptr);
}

AtomicTextFile::AtomicTextFile(const std::filesystem::path& file, bool overwrite)
    : file_(file), tmp_(file.string() + ".partial"), overwrite_(overwrite) {
  check_output_target(file, overwrite);
  if (file.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    if (ec)
      throw InputError(quote(file.parent_path()) + ": cannot create directory: " + ec.message());
  }
  fp_ = std::fopen(tmp_.c_str(), "wb");
  if (!fp_) throw InputError(quote(tmp_) + ": cannot create: " + std::strerror(errno));
  buf_.reserve(kFlushBytes + 4096);
}

AtomicTextFile::~AtomicTextFile() {
  if (fp_) std::fclose(fp_);
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicTextFile::write(std::string_view text) {
  buf_.append(text);
  maybe_flush();
}

void AtomicTextFile::maybe_flush() {
  if (buf_.size() >= kFlushBytes) flush();
}

void AtomicTextFile::flush() {
  if (buf_.empty()) return;
  if (std::fwrite(buf_.data(), 1, buf_.size(), fp_) != buf_.size())
    throw InputError(quote(tmp_) + ": write failed: " + std::strerror(errno));
  buf_.clear();
}

void AtomicTextFile::commit() {
  if (committed_) return;
  flush();
  const int rc = std::fclose(fp_);
  fp_ = nullptr;
  if (rc != 0) throw InputError(quote(tmp_) + ": close failed: " + std::strerror(errno));
  // The target may have appeared since the constructor looked.
  check_output_target(file_, overwrite_);
  std::error_code ec;
  std::filesystem::rename(tmp_, file_, ec);
  if (ec) throw InputError(quote(file_) + ": cannot move the finished file into place: " + ec.message());
  committed_ = true;
}

}  // namespace wheelins
