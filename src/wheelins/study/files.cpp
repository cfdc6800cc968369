// Files several processes write at once (files.hpp): the temporary names of results
// renamed into place, and the list of a report's files.
#include "wheelins/study/files.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
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
  write_file_atomic(dir_ / kReportList, text, shared_file(dir_ / kReportList));
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

AtomicFileOptions shared_file(const fs::path& file) {
  return {true, file.parent_path() / ("." + file.filename().string() + ".tmp-" + unique_suffix())};
}

}  // namespace wheelins::study
