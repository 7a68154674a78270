#include "pipeline/output_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "pipeline/label_outputs.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

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

// True if another open file description holds a lock on `path` (probed with a
// non-blocking shared lock, released at once).
bool LockedByOthers(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool locked = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return locked;
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

std::string FolderLockPath(const std::string& output_dir) {
  return output_dir + "/.handlabel.lock";
}

std::string ShardLockPath(const std::string& output_dir, const ShardSpec& shard) {
  const std::string log = ShardLogPath(output_dir, shard);
  return log.substr(0, log.size() - std::string(".jsonl").size()) + ".lock";
}

std::string OutputFolderLock::DescribeHolders(const std::string& output_dir) {
  std::string holders;
  const auto add = [&](const std::string& path) {
    if (!LockedByOthers(path)) return;
    const std::string holder = ReadLockHolder(path);
    holders += (holders.empty() ? "" : "; ") + (holder.empty() ? path : holder);
  };
  add(FolderLockPath(output_dir));
  std::error_code ignored;
  const fs::path shards = fs::path(output_dir) / "shards";
  std::vector<std::string> locks;
  for (const auto& e : fs::directory_iterator(shards, ignored)) {
    if (e.path().extension() == ".lock") locks.push_back(e.path().string());
  }
  std::sort(locks.begin(), locks.end());
  for (const std::string& path : locks) add(path);
  return holders.empty() ? "another process (it has just finished or not yet recorded "
                           "itself)"
                         : holders;
}

OutputFolderLock OutputFolderLock::ForShard(const std::string& output_dir,
                                            const ShardSpec& shard,
                                            const std::string& source) {
  fs::create_directories(fs::path(output_dir) / "shards");
  OutputFolderLock lock;
  lock.output_dir_ = output_dir;
  lock.source_ = source;
  lock.folder_ =
      FileLock::TryAcquire(FolderLockPath(output_dir), FileLock::Mode::kShared);
  if (!lock.folder_.held()) {
    throw InputError(source, "output.dir",
                     "an output folder no other process is writing (" + output_dir + ")",
                     "in use by " + DescribeHolders(output_dir));
  }
  const std::string shard_path = ShardLockPath(output_dir, shard);
  lock.shard_ = FileLock::TryAcquire(shard_path, FileLock::Mode::kExclusive);
  if (!lock.shard_.held()) {
    throw InputError(source, "output.dir",
                     "shard " + shard.ToString() + " of " + output_dir +
                         " not being labelled by another process",
                     "being labelled by " + ReadLockHolder(shard_path));
  }
  lock.shard_.RecordHolder("label shard " + shard.ToString());
  return lock;
}

OutputFolderLock OutputFolderLock::Whole(const std::string& output_dir,
                                         const std::string& command,
                                         const std::string& source) {
  fs::create_directories(output_dir);
  OutputFolderLock lock;
  lock.output_dir_ = output_dir;
  lock.source_ = source;
  lock.folder_ =
      FileLock::TryAcquire(FolderLockPath(output_dir), FileLock::Mode::kExclusive);
  if (!lock.folder_.held()) {
    throw InputError(source, "output.dir",
                     "an output folder no other process is writing (" + output_dir +
                         ") for " + command,
                     "in use by " + DescribeHolders(output_dir));
  }
  lock.folder_.RecordHolder(command);
  return lock;
}

void OutputFolderLock::MakeWhole(const std::string& why) {
  if (folder_.TryMakeExclusive()) return;
  // Our own shard lock is held through another descriptor: leave it out of the list.
  FileLock own = std::move(shard_);
  own = FileLock();
  throw InputError(source_, "output.dir",
                   "no other process writing " + output_dir_ + " (to " + why + ")",
                   "in use by " + DescribeHolders(output_dir_));
}

}  // namespace handlabel
