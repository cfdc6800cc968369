// Exact number formatting and strict parsing (text_util.hpp), and the text helpers of io.
#include "wheelins/io/text_util.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "wheelins/io/diagnostics.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {

WarningSink stderr_sink() {
  // Whole lines, each once: what stdout holds so far goes out first (a log that takes both
  // gets no warning in the middle of a line), and a message said before is not repeated.
  struct Said {
    std::mutex lock;
    std::set<std::string> messages;
  };
  auto said = std::make_shared<Said>();
  return [said](const std::string& message) {
    const std::lock_guard<std::mutex> hold(said->lock);
    if (!said->messages.insert(message).second) return;
    std::cout.flush();
    std::fflush(stdout);
    std::cerr << "warning: " << message << "\n";
    std::cerr.flush();
  };
}

namespace io_detail {

std::string json_quote(std::string_view s) {
  std::string o = "\"";
  for (char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\t': o += "\\t"; break;
      case '\r': o += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          static const char* hex = "0123456789abcdef";
          o += "\\u00";
          o += hex[(c >> 4) & 0xf];
          o += hex[c & 0xf];
        } else {
          o += c;
        }
    }
  }
  o += '"';
  return o;
}

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

std::filesystem::path unique_partial(const std::filesystem::path& file) {
  static std::atomic<unsigned long> counter{0};
  return file.string() + ".partial-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

std::vector<std::string> sweep_stale_partials(const std::filesystem::path& dir,
                                              const std::vector<std::string>& names) {
  std::vector<std::string> removed;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    const std::size_t at = n.rfind(".partial-");
    if (at == std::string::npos || at == 0) continue;
    if (!names.empty() && std::find(names.begin(), names.end(), n.substr(0, at)) == names.end()) continue;
    // NAME.partial-PID-N: digits, a dash, digits, nothing else.
    const char* p = n.c_str() + at + 9;
    char* end = nullptr;
    const long pid = std::strtol(p, &end, 10);
    if (end == p || *end != '-' || !std::isdigit(static_cast<unsigned char>(end[1]))) continue;
    const char* q = end + 1;
    while (std::isdigit(static_cast<unsigned char>(*q))) ++q;
    if (*q != '\0' || pid <= 0) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM) continue;  // its writer is running
    std::error_code rm;
    if (e.is_regular_file(rm) && std::filesystem::remove(e.path(), rm)) removed.push_back(n);
  }
  return removed;
}

bool bounded_getline(std::istream& in, std::string& line, std::size_t max_len,
                     const std::string& where) {
  line.resize(max_len + 1);
  in.getline(line.data(), static_cast<std::streamsize>(max_len + 1));
  const auto n = static_cast<std::size_t>(in.gcount());
  if (in.bad()) {
    line.clear();
    return false;
  }
  if (in.fail()) {
    if (n == 0) {  // nothing extracted: the end
      line.clear();
      return false;
    }
    throw InputError(where + ": a line longer than " + std::to_string(max_len) +
                     " characters: not a text file of this kind (binary data, or a device?)");
  }
  line.resize(in.eof() ? n : n - 1);  // gcount counts the extracted newline
  // A mark on the first line: the stream is now just past this line (a stream without a
  // position, a pipe, keeps its mark).
  if (line.compare(0, 3, "\xEF\xBB\xBF") == 0 && in.rdbuf() &&
      in.rdbuf()->pubseekoff(0, std::ios::cur, std::ios::in) == std::streampos(static_cast<std::streamoff>(n)))
    line.erase(0, 3);
  return true;
}

std::uint64_t check_input_file(const std::filesystem::path& file, const std::string& expected) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) {
    const int err = errno;
    struct stat lst {};
    const bool is_link = ::lstat(file.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode);
    if (err == ELOOP)
      throw InputError(quote(file) + ": too many levels of symbolic links (a loop of links?); "
                       "expected " + expected);
    if (err == ENOENT && is_link)
      throw InputError(quote(file) + ": is a symbolic link to a file that does not exist");
    if (err == ENOENT) throw InputError(quote(file) + ": file not found");
    if (err == ENOTDIR)
      throw InputError(quote(file) + ": file not found (a part of the path is not a directory)");
    if (err == EACCES) throw InputError(quote(file) + ": permission denied");
    throw InputError(quote(file) + ": cannot read: " + std::strerror(err));
  }
  if (S_ISDIR(st.st_mode)) throw InputError(quote(file) + ": is a directory, expected " + expected);
  if (!S_ISREG(st.st_mode)) {
    const char* what = S_ISFIFO(st.st_mode)   ? "a FIFO (named pipe)"
                       : S_ISCHR(st.st_mode)  ? "a character device"
                       : S_ISBLK(st.st_mode)  ? "a block device"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                                              : "not a regular file";
    throw InputError(quote(file) + ": is " + std::string(what) + ", expected " + expected +
                     " (wheelins reads regular files only)");
  }
  if (::access(file.c_str(), R_OK) != 0)
    throw InputError(quote(file) + ": cannot open: " + std::strerror(errno));
  return static_cast<std::uint64_t>(st.st_size);
}

std::string format_double(double v) {
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  // Shortest may pick "1e+05" for 100000: people read plain digits better in the usual range.
  const double a = std::abs(v);
  if (std::memchr(buf, 'e', static_cast<std::size_t>(res.ptr - buf)) && a >= 1e-5 && a < 1e16)
    res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  return std::string(buf, res.ptr);
}

std::string format_long_double(long double v) {
  char buf[128];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

namespace {
template <class T>
std::optional<T> parse_number(std::string_view s) {
  const auto is_blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty() || s.front() == '+') return std::nullopt;
  T v = 0;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  if (res.ec == std::errc::result_out_of_range) return std::nullopt;
  if (res.ec != std::errc() || res.ptr != s.data() + s.size()) {
    // YAML spells the special values .inf / -.inf / .nan.
    std::string low(s);
    std::transform(low.begin(), low.end(), low.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (low == ".nan") return std::numeric_limits<T>::quiet_NaN();
    if (low == ".inf") return std::numeric_limits<T>::infinity();
    if (low == "-.inf") return -std::numeric_limits<T>::infinity();
    return std::nullopt;
  }
  return v;
}
}  // namespace

std::optional<double> parse_double(std::string_view s) { return parse_number<double>(s); }
std::optional<long double> parse_long_double(std::string_view s) {
  return parse_number<long double>(s);
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

void split_fields(std::string_view line, char sep, std::vector<std::string_view>& out) {
  out.clear();
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  if (sep == ' ') {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && blank(line[i])) ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && !blank(line[j])) ++j;
      out.push_back(line.substr(i, j - i));
      i = j;
    }
    return;
  }
  std::size_t start = 0;
  for (;;) {
    const std::size_t k = line.find(sep, start);
    out.push_back(line.substr(start, k == std::string_view::npos ? std::string_view::npos : k - start));
    if (k == std::string_view::npos) break;
    start = k + 1;
  }
}

}  // namespace io_detail
}  // namespace wheelins
