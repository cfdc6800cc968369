// Advisory locks (file_lock.hpp).
#include "wheelins/io/file_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "wheelins/nav/types.hpp"

namespace wheelins {

FileLock::FileLock(const std::filesystem::path& path, Wait wait) {
  std::error_code ec;
  const bool dir = std::filesystem::is_directory(path, ec);
  fd_ = dir ? ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)
            : ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw InputError("'" + path.string() + "': cannot open " + (dir ? "the directory" : "the lock file") +
                     " to lock it: " + std::strerror(errno));
  const int how = wait == Wait::kUntilFree ? LOCK_EX : LOCK_EX | LOCK_NB;
  while (::flock(fd_, how) != 0) {
    if (errno == EINTR) continue;
    error_ = errno;
    state_ = error_ == EWOULDBLOCK ? State::kHeldElsewhere : State::kNoLocks;
    return;
  }
  state_ = State::kLocked;
}

void FileLock::release() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace wheelins
