#include "core/file_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>

#include "core/errors.h"

namespace handlabel {
namespace {

std::string HostName() {
  char name[256] = {};
  if (gethostname(name, sizeof(name) - 1) != 0) return "unknown";
  return name;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace

FileLock FileLock::TryAcquire(const std::string& path, Mode mode) {
  FileLock lock;
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw InputError(path, "", "a lock file the output folder's writer can create",
                     std::strerror(errno));
  }
  const int operation = (mode == Mode::kShared ? LOCK_SH : LOCK_EX) | LOCK_NB;
  if (::flock(fd, operation) != 0) {
    const int error = errno;
    ::close(fd);
    if (error == EWOULDBLOCK) return lock;
    throw InputError(path, "", "a lockable file (flock)", std::strerror(error));
  }
  lock.fd_ = fd;
  lock.path_ = path;
  return lock;
}

FileLock::FileLock(FileLock&& other) noexcept : fd_(other.fd_), path_(other.path_) {
  other.fd_ = -1;
}

FileLock& FileLock::operator=(FileLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    other.fd_ = -1;
  }
  return *this;
}

FileLock::~FileLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the last descriptor releases the flock
}

bool FileLock::TryMakeExclusive() {
  return fd_ >= 0 && ::flock(fd_, LOCK_EX | LOCK_NB) == 0;
}

void FileLock::RecordHolder(const std::string& what) const {
  if (fd_ < 0) return;
  const std::string text = what + ", pid " + std::to_string(::getpid()) + " on host " +
                           HostName() + " since " + UtcNow() + "\n";
  // Best effort: the lock itself is the flock; the text only helps the message.
  if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, text.data(), text.size(), 0) >= 0) {
    ::fsync(fd_);
  }
}

std::string ReadLockHolder(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

bool LockedByOthers(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool locked = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return locked;
}

std::string FolderLockPath(const std::string& dir) {
  return (std::filesystem::path(dir) / ".handlabel.lock").string();
}

FileLock LockFolderForWriting(const std::string& dir, const std::string& what,
                              const std::string& source, const std::string& field) {
  return LockFolderForWriting(dir, FolderLockPath(dir), what, source, field);
}

FileLock LockFolderForWriting(const std::string& dir, const std::string& path,
                              const std::string& what, const std::string& source,
                              const std::string& field) {
  FileLock lock = FileLock::TryAcquire(path, FileLock::Mode::kExclusive);
  if (!lock.held()) {
    const std::string holder = ReadLockHolder(path);
    throw InputError(source, field, "a folder no other process is writing (" + dir + ")",
                     "in use by " + (holder.empty() ? "another process (it has just "
                                                      "started or finished)"
                                                    : holder));
  }
  lock.RecordHolder(what);
  return lock;
}

}  // namespace handlabel
