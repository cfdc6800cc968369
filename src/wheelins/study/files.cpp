// Files several processes write at once (files.hpp): results written to a temporary file
// renamed into place, and the lock file one dataset generator holds.
#include "wheelins/study/files.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "wheelins/nav/types.hpp"

namespace wheelins::study {
namespace fs = std::filesystem;

std::string host_name() {
  char host[256] = "";
  if (::gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') return "host";
  host[sizeof host - 1] = '\0';
  return host;
}

std::string unique_suffix() {
  static std::atomic<unsigned> counter{0};
  return host_name() + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

namespace {
constexpr const char* kReportList = ".wheelins-report";
std::string first_line_of(const std::string& text) { return text.substr(0, text.find('\n')); }
}  // namespace

ReportFiles::ReportFiles(const fs::path& dir) : dir_(dir) {
  std::string text;
  listed_ = read_file(dir / kReportList, text);
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) names_.push_back(line);
}

void ReportFiles::check(const fs::path& rel, const std::string& first_line) const {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dir_ / rel, ec))) return;
  const std::string name = rel.generic_string();
  if (std::find(names_.begin(), names_.end(), name) != names_.end()) return;
  std::string old;
  if (!listed_ && !first_line.empty() && read_file(dir_ / rel, old) && first_line_of(old) == first_line) return;
  throw InputError("'" + (dir_ / rel).string() + "': not written by a study report; refusing to replace it, "
                   "with or without --force (move it away, or give the study another `results` directory)");
}

void ReportFiles::add(const std::vector<fs::path>& rels) {
  for (const auto& r : rels) {
    const std::string name = r.generic_string();
    if (std::find(names_.begin(), names_.end(), name) == names_.end()) names_.push_back(name);
  }
  std::string text;
  for (const auto& n : names_) text += n + "\n";
  write_file_atomic(dir_ / kReportList, text);
  listed_ = true;
}

bool read_file(const fs::path& file, std::string& out) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  out = ss.str();
  return static_cast<bool>(in) || in.eof();
}

void write_file_atomic(const fs::path& file, std::string_view text,
                       const ChunkWriter& write_chunk) {
  const fs::path tmp =
      file.parent_path() / ("." + file.filename().string() + ".tmp-" + unique_suffix());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError("'" + tmp.string() + "': cannot create: " + std::strerror(errno));
  constexpr std::size_t kChunk = 1 << 16;
  try {
    for (std::size_t pos = 0; pos < text.size(); pos += kChunk) {
      const std::string_view chunk = text.substr(pos, kChunk);
      if (write_chunk) {
        write_chunk(fd, chunk);
        continue;
      }
      std::size_t done = 0;
      while (done < chunk.size()) {
        const ssize_t n = ::write(fd, chunk.data() + done, chunk.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
          throw InputError("'" + file.string() + "': cannot write: " + std::strerror(errno));
        done += static_cast<std::size_t>(n);
      }
    }
  } catch (...) {
    ::close(fd);
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  if (::close(fd) != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw InputError("'" + file.string() + "': cannot close: " + std::strerror(errno));
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError("'" + file.string() + "': cannot move into place: " + ec.message());
  }
}

FileLock::FileLock(const fs::path& file) {
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw InputError("'" + file.string() +
                     "': cannot create the lock file: " + std::strerror(errno));
  while (::flock(fd_, LOCK_EX) != 0) {
    if (errno == EINTR) continue;
    return;  // no locks on this file system (ENOLCK, EOPNOTSUPP, ...): locked() stays false
  }
  locked_ = true;
}

FileLock::~FileLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

}  // namespace wheelins::study
