// The all-or-nothing output directory of output_dir.hpp: staging, locking, and the move
// into place.
#include "wheelins/io/output_dir.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <system_error>

#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins {
namespace fs = std::filesystem;
using io_detail::quote;

namespace {

bool has_suffix(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// Output directories written before the marker existed, recognised by their files.
std::string legacy_kind(const fs::path& dir) {
  std::error_code ec;
  bool all_results = true, any_result = false;
  bool manifest = false, scenario = false, experiment = false;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n == "manifest.yaml") manifest = true;
    if (n == "scenario.yaml") scenario = true;
    if (n == "experiment.json" || n == "experiment.md" || n == "runs.csv") experiment = true;
    const bool result_file = e.is_regular_file(ec) &&
                             (n == "trajectory.csv" || n == "trajectory.tum" || n == "trajectory.kml" ||
                              n == "faults.csv" || has_suffix(n, ".csv"));
    if (n == "faults.csv" || n.rfind("trajectory.", 0) == 0) any_result = true;
    if (!result_file) all_results = false;
  }
  if (manifest && scenario) {
    std::ifstream in(dir / "manifest.yaml");
    std::string line;
    for (int i = 0; i < 4 && std::getline(in, line); ++i)
      if (line.find("simulated by wheelins simulate") != std::string::npos) return "dataset";
  }
  if (experiment) return "experiment";
  if (all_results && any_result) return "results";
  return "foreign";
}

bool process_alive(long pid) {
  if (pid <= 0) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

/// Removes staging directories of `name` in `parent` left by writers that are gone.
void sweep_stale(const fs::path& parent, const std::string& name) {
  const std::string prefixes[] = {"." + name + ".partial-", "." + name + ".old-"};
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(parent, ec)) {
    const std::string n = e.path().filename().string();
    for (const auto& p : prefixes) {
      if (n.rfind(p, 0) != 0) continue;
      const long pid = std::strtol(n.c_str() + p.size(), nullptr, 10);
      if (!process_alive(pid)) {
        std::error_code ec2;
        fs::remove_all(e.path(), ec2);
      }
    }
  }
}

bool inside(const fs::path& file, const fs::path& dir) {
  std::error_code ec;
  const fs::path f = fs::weakly_canonical(file, ec);
  if (ec) return false;
  const fs::path d = fs::weakly_canonical(dir, ec);
  if (ec) return false;
  auto fi = f.begin();
  for (auto di = d.begin(); di != d.end(); ++di, ++fi)
    if (di->empty() && std::next(di) == d.end()) break;  // trailing separator
    else if (fi == f.end() || *fi != *di) return false;
  return true;
}

std::string with_article(const std::string& kind) {
  if (kind == "results") return kind;
  return (kind == "experiment" ? "an " : "a ") + kind;
}

/// The entries a marker lists as written by wheelins ("file NAME" lines), or nothing if the
/// marker predates the list.
std::optional<std::set<std::string>> written_entries(const fs::path& dir) {
  std::ifstream in(dir / kOutputMarker);
  std::string line;
  std::set<std::string> names;
  bool listed = false;
  while (std::getline(in, line)) {
    if (line == "files:") listed = true;
    else if (listed && line.rfind("- ", 0) == 0) names.insert(line.substr(2));
  }
  if (!listed) return std::nullopt;
  return names;
}

std::string first_entry(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) return e.path().filename().string();
  return "";
}

}  // namespace

std::string output_dir_kind(const fs::path& dir) {
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  if (!fs::exists(st)) return "";
  if (!fs::is_directory(st)) return "not a directory";
  if (fs::is_empty(dir, ec)) return "";
  std::ifstream marker(dir / kOutputMarker);
  std::string line;
  if (marker && std::getline(marker, line) && line.rfind("wheelins ", 0) == 0) return line.substr(9);
  return legacy_kind(dir);
}

OutputDir::OutputDir(const fs::path& target, const OutputDirOptions& options) : opt_(options) {
  if (target.empty()) throw InputError("no output directory given");
  target_ = fs::absolute(target).lexically_normal();
  if (target_.filename().empty()) target_ = target_.parent_path();
  const std::string q = quote(target);
  std::error_code lec;
  if (fs::is_symlink(fs::symlink_status(target_, lec))) {
    // Followed: the output goes where the link points, and the link stays a link.
    const fs::path to = fs::canonical(target_, lec);
    if (lec)
      throw InputError(q + ": a symbolic link to " + quote(fs::read_symlink(target_, lec)) +
                       ", which does not exist (create that directory, or give another output directory)");
    target_ = to;
  }
  const fs::path parent = target_.parent_path();
  const std::string name = target_.filename().string();

  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec)
    throw InputError(quote(parent) + ": cannot create the directory for " + q + ": " + ec.message());
  if (::access(parent.c_str(), W_OK | X_OK) != 0)
    throw InputError(q + ": cannot write in " + quote(parent) + " (" + std::strerror(errno) +
                     "); choose another output directory");

  const std::string kind = output_dir_kind(target_);
  if (kind == "not a directory") throw InputError(q + ": exists and is not a directory");
  if (kind == opt_.kind) {
    if (!opt_.overwrite)
      throw InputError(q + ": already holds " + opt_.kind + " of an earlier command; refusing to "
                       "overwrite them (" + opt_.overwrite_hint + " replaces the files wheelins wrote there "
                       "and keeps the rest, or choose another directory)");
    replace_ = true;
  } else if (kind == "foreign") {
    throw InputError(q + ": holds files that wheelins did not write (e.g. '" + first_entry(target_) +
                     "'); choose a new or empty directory (nothing there is replaced, even with " +
                     opt_.overwrite_hint + ")");
  } else if (!kind.empty()) {
    throw InputError(q + ": holds wheelins " + kind + " (not " + with_article(opt_.kind) +
                     "); refusing to replace it (choose another directory)");
  }
  if (replace_)
    for (const auto& in : opt_.inputs)
      if (inside(in, target_))
        throw InputError(q + ": holds " + quote(in) + ", an input of this command; replacing the "
                         "directory would destroy it (copy it elsewhere first, or choose another "
                         "output directory)");

  if (::mkdir(target_.c_str(), 0777) == 0) created_target_ = true;
  else if (errno != EEXIST)
    throw InputError(q + ": cannot create: " + std::strerror(errno));
  try {
    lock_.emplace(target_, FileLock::Wait::kNo);
    if (lock_->state() == FileLock::State::kHeldElsewhere)
      throw InputError(q + ": another wheelins command is writing there right now; wait for it "
                       "to finish or choose another output directory");
    if (!lock_->locked()) throw InputError(q + ": cannot lock: " + std::strerror(lock_->error()));
    sweep_stale(parent, name);
    std::string tmpl =
        (parent / ("." + name + ".partial-" + std::to_string(::getpid()) + "-XXXXXX")).string();
    if (!::mkdtemp(tmpl.data()))
      throw InputError(q + ": cannot create a staging directory in " + quote(parent) + ": " +
                       std::strerror(errno));
    staging_ = tmpl;
  } catch (...) {
    cleanup();
    throw;
  }
}

void OutputDir::cleanup() noexcept {
  std::error_code ec;
  if (!committed_ && !staging_.empty()) fs::remove_all(staging_, ec);
  if (!committed_ && created_target_) ::rmdir(target_.c_str());  // only if still empty
  created_target_ = false;
  staging_.clear();
  lock_.reset();
}

OutputDir::~OutputDir() { cleanup(); }

void OutputDir::replace_target(const std::string& q) {
#ifdef RENAME_EXCHANGE
  const bool exchanged =
      ::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0;
#else
  const bool exchanged = false;
#endif
  std::error_code ec;
  if (exchanged) {
    fs::remove_all(staging_, ec);  // now the earlier output
    return;
  }
  // No atomic exchange on this file system: the old output steps aside first.
  const fs::path old =
      target_.parent_path() / ("." + target_.filename().string() + ".old-" + std::to_string(::getpid()));
  if (::rename(target_.c_str(), old.c_str()) != 0)
    throw InputError(q + ": cannot move the finished " + opt_.kind + " into place: " + std::strerror(errno));
  if (::rename(staging_.c_str(), target_.c_str()) != 0) {
    const int err = errno;
    ::rename(old.c_str(), target_.c_str());
    throw InputError(q + ": cannot move the finished " + opt_.kind + " into place: " + std::strerror(err));
  }
  fs::remove_all(old, ec);
}

void OutputDir::commit() {
  if (committed_) return;
  const std::string q = quote(target_);
  std::error_code ec;
  std::set<std::string> written;
  for (const auto& e : fs::directory_iterator(staging_, ec)) written.insert(e.path().filename().string());
  {
    std::FILE* f = std::fopen((staging_ / kOutputMarker).c_str(), "wb");
    if (!f) throw InputError(quote(staging_) + ": cannot write: " + std::strerror(errno));
    // The first line says what the directory holds; the list, what wheelins wrote there
    // (all a later --force may replace).
    std::string text = "wheelins " + opt_.kind + "\nfiles:\n";
    for (const auto& n : written) text += "- " + n + "\n";
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !ok)
      throw InputError(quote(staging_) + ": write failed: " + std::strerror(errno));
  }
  const std::string kind = output_dir_kind(target_);
  if (kind.empty()) {
    if (::rename(staging_.c_str(), target_.c_str()) != 0)
      throw InputError(q + ": cannot move the finished " + opt_.kind + " into place: " +
                       std::strerror(errno) + " (another command wrote there meanwhile?)");
  } else if (kind == opt_.kind && opt_.overwrite) {
    // What the earlier output holds that wheelins did not write (the marker's list; an
    // older marker without one: whatever this output does not write again) moves into the
    // new output, so that replacing it loses nothing of the user's.
    const auto listed = written_entries(target_);
    std::vector<std::string> keep;
    for (const auto& e : fs::directory_iterator(target_, ec)) {
      const std::string n = e.path().filename().string();
      if (n == kOutputMarker || (listed ? listed->count(n) > 0 : written.count(n) > 0)) continue;
      if (written.count(n))
        throw InputError(q + ": holds '" + n + "', which wheelins did not write there and this " + opt_.kind +
                         " would replace; move it away first (nothing was changed)");
      keep.push_back(n);
    }
    std::size_t moved = 0;
    auto put_back = [&] {
      for (std::size_t i = 0; i < moved; ++i) {
        std::error_code ec2;
        fs::rename(staging_ / keep[i], target_ / keep[i], ec2);
      }
    };
    for (; moved < keep.size(); ++moved) {
      fs::rename(target_ / keep[moved], staging_ / keep[moved], ec);
      if (ec) {
        put_back();
        throw InputError(q + ": cannot keep '" + keep[moved] + "' (not written by wheelins): " + ec.message() +
                         "; nothing was replaced");
      }
    }
    try {
      replace_target(q);
    } catch (...) {
      put_back();
      throw;
    }
    kept_ = keep;
    if (opt_.notice && !keep.empty()) {
      std::string list;
      for (const auto& n : keep) list += (list.empty() ? "'" : ", '") + n + "'";
      opt_.notice(q + ": replaced the earlier " + opt_.kind + " and kept what wheelins did not write there: " + list);
    }
  } else if (kind == opt_.kind) {
    throw InputError(q + ": another command wrote " + opt_.kind + " there meanwhile; refusing to "
                     "overwrite them (" + opt_.overwrite_hint + " replaces them)");
  } else {
    throw InputError(q + ": changed while this command ran (now holds " +
                     (kind == "foreign" ? std::string("other files") : "a " + kind) +
                     "); nothing was moved there");
  }
  committed_ = true;
  staging_.clear();
  lock_.reset();
}

}  // namespace wheelins
