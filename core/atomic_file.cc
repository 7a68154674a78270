#include "core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/errors.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Fail(const std::string& what, const std::string& path) {
  throw Error(what + " '" + path + "': " + std::strerror(errno));
}

void WriteAll(int fd, const std::string& content, const std::string& path) {
  size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ::close(fd);
      Fail("cannot write", path);
    }
    done += static_cast<size_t>(n);
  }
}

void SyncDirectory(const fs::path& dir) {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& content) {
  const fs::path target(path);
  if (target.has_parent_path()) fs::create_directories(target.parent_path());
  const std::string temp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) Fail("cannot create", temp);
  // A failed write (a full disk) names the file meant and leaves no temporary behind.
  try {
    WriteAll(fd, content, path);
    if (::fsync(fd) != 0) {
      ::close(fd);
      Fail("cannot flush", path);
    }
    ::close(fd);
    if (::rename(temp.c_str(), path.c_str()) != 0) Fail("cannot rename into", path);
  } catch (...) {
    ::unlink(temp.c_str());
    throw;
  }
  SyncDirectory(target.parent_path());
}

void AppendLineDurably(const std::string& path, const std::string& line) {
  const fs::path target(path);
  if (target.has_parent_path()) fs::create_directories(target.parent_path());
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) Fail("cannot open", path);
  WriteAll(fd, line + "\n", path);
  if (::fsync(fd) != 0) {
    ::close(fd);
    Fail("cannot flush", path);
  }
  ::close(fd);
}

int RemoveStaleTemporaries(const std::string& dir) {
  int removed = 0;
  if (!fs::is_directory(dir)) return 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.find(".tmp.") != std::string::npos) {
      fs::remove(entry.path());
      ++removed;
    }
  }
  return removed;
}

}  // namespace handlabel
