// Atomic output files (atomic_file.hpp): the temporary name, commit and the refusal to
// overwrite; the fast fixed-notation number writer.
#include "wheelins/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <system_error>

#include "wheelins/io/text_util.hpp"
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

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ca.empty() && ca == cb;
}

std::vector<NamedFile> named_files(const std::vector<std::filesystem::path>& files, const std::string& name) {
  std::vector<NamedFile> out;
  for (const auto& f : files) out.push_back({f, name});
  return out;
}

void check_output_files(const std::vector<OutputFile>& outputs, const std::vector<NamedFile>& inputs,
                        bool overwrite) {
  auto named = [](const NamedFile& o) { return (o.name.empty() ? "" : o.name + " ") + quote(o.file); };
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const OutputFile& o = outputs[i];
    if (o.file.empty())
      throw InputError((o.name.empty() ? std::string("an output file") : o.name) + ": an empty file name");
    for (const auto& in : inputs)
      if (same_file(o.file, in.file))
        throw InputError(named(o) + ": is " + (in.name.empty() ? quote(in.file) : named(in)) +
                         ", an input of this command; an output never replaces an input, with or without --force "
                         "(choose another file)");
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(o.file, outputs[j].file))
        throw InputError(named(o) + ": the same file as " + named(outputs[j]) + "; give each output its own file");
    std::error_code ec;
    const auto st = std::filesystem::status(o.file, ec);
    if (std::filesystem::is_directory(st))
      throw InputError(named(o) + ": is a directory, expected an output file name");
    if (std::filesystem::exists(st) && !overwrite)
      throw InputError(named(o) + ": already exists; refusing to overwrite it (--force replaces it, or choose "
                       "another name)");
  }
}

namespace {

constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,
                             1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19};

/// The integer nearest to the exact product a * s (a >= 0, s an exact power of ten), ties
/// to even. prod = fl(a s) may sit on the wrong side of a half; err = a s - prod is exact
/// (fma), and so are the comparisons below.
double nearest_integer(double a, double s) {
  const double prod = a * s;
  const double err = std::fma(a, s, -prod);
  double r = std::nearbyint(prod);
  const double d = prod - r;  // exact, in [-0.5, 0.5]; the exact a s - r is d + err
  const double up = 0.5 - d, down = -0.5 - d;  // exact
  if (err > up || (err == up && std::fmod(r, 2.0) != 0.0)) return r + 1.0;
  if (err < down || (err == down && std::fmod(r, 2.0) != 0.0)) return r - 1.0;
  return r;
}

/// Writes `significant` digits of `value` in the general format (as std::to_chars with
/// chars_format::general) for the common case where that format is fixed notation
/// (1e-4 <= |value| < 10^significant, significant <= 12), returning the end; nullptr
/// otherwise. About 4 times faster than to_chars: the digits are the integer nearest to
/// the exact product |value| * 10^k (10^k is exact; the product's rounding error is
/// recovered with fma), ties to even, so they are correctly rounded like to_chars'
/// (IoText.SignificantDigitsMatchToChars checks it against to_chars).
char* significant_fixed(char* dst, double value, int significant) {
  const double a = std::fabs(value);
  if (significant < 1 || significant > 12 || !(a >= 1e-4 && a < kPow10[significant])) return nullptr;
  int bexp = 0;
  std::frexp(a, &bexp);  // a in [2^(bexp-1), 2^bexp)
  int e = static_cast<int>(std::floor((bexp - 1) * 0.30102999566398120));  // e or e - 1
  if (e < -4) e = -4;
  double digits = 0.0;
  for (int pass = 0; pass < 3; ++pass) {
    const int k = significant - 1 - e;  // decimals in fixed notation, 0 .. significant + 3
    if (k < 0 || k > 19) return nullptr;
    digits = nearest_integer(a, kPow10[k]);
    if (digits >= kPow10[significant]) {
      ++e;  // one digit too many (e was one low, or rounding carried into a new digit)
      continue;
    }
    if (digits < kPow10[significant - 1]) {
      --e;
      continue;
    }
    break;
  }
  if (e < -4 || e >= significant || digits < kPow10[significant - 1] ||
      digits >= kPow10[significant])
    return nullptr;
  char buf[32];
  char* end = buf + sizeof buf;
  char* p = end;
  auto n = static_cast<std::uint64_t>(digits);
  int decimals = significant - 1 - e;
  // Trailing zeros of the fraction are not written (general format).
  while (decimals > 0 && n % 10 == 0) {
    n /= 10;
    --decimals;
  }
  for (int i = 0; i < decimals; ++i) {
    *--p = static_cast<char>('0' + n % 10);
    n /= 10;
  }
  if (decimals > 0) *--p = '.';
  if (e >= 0) {
    do {
      *--p = static_cast<char>('0' + n % 10);
      n /= 10;
    } while (n);
  } else {
    *--p = '0';  // 0.000ddd: the fraction loop wrote the leading zeros (n ran out)
  }
  if (value < 0) *--p = '-';
  const auto len = static_cast<std::size_t>(end - p);
  std::memcpy(dst, p, len);
  return dst + len;
}

}  // namespace

char* write_double(char* dst, double value, int significant) {
  significant = std::min(significant, 17);  // a double has no more; fits kMaxDoubleChars
  if (std::isnan(value)) {
    std::memcpy(dst, "nan", 3);
    return dst + 3;
  }
  if (significant > 0)
    if (char* end = significant_fixed(dst, value, significant)) return end;
  const auto res = significant > 0 ? std::to_chars(dst, dst + kMaxDoubleChars, value,
                                                   std::chars_format::general, significant)
                                   : std::to_chars(dst, dst + kMaxDoubleChars, value);
  return res.ptr;
}

void append_double(std::string& out, double value, int significant) {
  char buf[kMaxDoubleChars];
  out.append(buf, write_double(buf, value, significant));
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

AtomicFile::AtomicFile(const std::filesystem::path& file, const AtomicFileOptions& options)
    : file_(file),
      tmp_(options.temporary.empty() ? io_detail::unique_partial(file) : options.temporary),
      overwrite_(options.overwrite) {
  check_output_target(file, overwrite_);
  if (file.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    if (ec)
      throw InputError(quote(file.parent_path()) + ": cannot create directory: " + ec.message());
  }
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) throw InputError(quote(tmp_) + ": cannot create: " + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::write(const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd_, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw InputError(quote(file_) + ": write failed: " + std::strerror(n < 0 ? errno : ENOSPC));
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
}

void AtomicFile::commit() {
  if (committed_) return;
  const int rc = ::close(fd_);
  fd_ = -1;
  if (rc != 0) throw InputError(quote(file_) + ": close failed: " + std::strerror(errno));
  move_into_place(tmp_, file_, overwrite_);
  committed_ = true;
}

void move_into_place(const std::filesystem::path& temporary, const std::filesystem::path& file,
                     bool overwrite) {
  std::error_code ec;
  try {
    check_output_target(file, overwrite);  // the target may have appeared since the writer looked
  } catch (...) {
    std::filesystem::remove(temporary, ec);
    throw;
  }
  std::filesystem::rename(temporary, file, ec);
  if (ec) {
    std::error_code ec2;
    std::filesystem::remove(temporary, ec2);
    throw InputError(quote(file) + ": cannot move the finished file into place: " + ec.message());
  }
}

void write_file_atomic(const std::filesystem::path& file, std::string_view text,
                       const AtomicFileOptions& options, const ChunkWriter& write_chunk) {
  AtomicFile out(file, options);
  constexpr std::size_t kChunk = 1 << 16;
  for (std::size_t pos = 0; pos < text.size(); pos += kChunk) {
    const std::string_view chunk = text.substr(pos, kChunk);
    if (write_chunk) write_chunk(out.fd(), chunk);
    else out.write(chunk);
  }
  out.commit();
}

AtomicTextFile::AtomicTextFile(const std::filesystem::path& file, bool overwrite)
    : out_(file, AtomicFileOptions{overwrite, {}}) {
  buf_.reserve(kFlushBytes + 4096);
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
  out_.write(buf_);
  buf_.clear();
}

void AtomicTextFile::commit() {
  if (out_.committed()) return;
  flush();
  out_.commit();
}

}  // namespace wheelins
