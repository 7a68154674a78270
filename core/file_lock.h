#pragma once
// One writer per output: advisory locks (flock) on a file in the folder written, which
// the kernel releases when the holder dies, so a lock left by kill -9 never blocks the
// next run (the file stays, with its last holder's details, and is simply locked
// again). The holder writes "<what>, pid <pid> on host <host> since <UTC time>" into
// the file, so that the process refused can say who holds the folder.
//
// Users: a capture folder (`capture init --overwrite`, `capture import`, `detect
// --capture`), a `detect --images` output folder, a training run folder (`train`), an
// `adapt` run folder, a label output folder and its shards (pipeline/output_lock.h). A
// lock is per open file: a second lock of the same file in one process conflicts with the
// first like another process's would.

#include <string>

namespace handlabel {

// A held flock on one file; releases it (closes the file) when destroyed.
class FileLock {
 public:
  enum class Mode { kShared, kExclusive };
  // Locks `path` (created if missing) without waiting. Returns an empty lock (held()
  // false) when another process holds a conflicting lock. Throws InputError when the
  // file cannot be opened.
  static FileLock TryAcquire(const std::string& path, Mode mode);
  FileLock() = default;
  FileLock(FileLock&& other) noexcept;
  FileLock& operator=(FileLock&& other) noexcept;
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock();

  bool held() const { return fd_ >= 0; }
  // Converts a held shared lock to exclusive without waiting; false if others hold it
  // too (the shared lock is then kept where the kernel allows, else released).
  bool TryMakeExclusive();
  // Writes "<what>, pid <pid> on host <host> since <UTC time>" into the file, for
  // the error another process gives.
  void RecordHolder(const std::string& what) const;

 private:
  int fd_ = -1;
  std::string path_;
};

// The holder details recorded in a lock file ("" if none).
std::string ReadLockHolder(const std::string& path);

// True if another open file description holds a lock on `path` (probed with a
// non-blocking shared lock, released at once).
bool LockedByOthers(const std::string& path);

// `dir`/.handlabel.lock: the lock file of a folder's writer.
std::string FolderLockPath(const std::string& dir);

// Locks the folder `dir` (which must exist) for one writer: an exclusive lock on
// FolderLockPath(dir) recording `what` (e.g. "capture import"). Throws InputError
// naming `source` and `field` (may be ""), the folder and the holder's details when
// another process holds it.
FileLock LockFolderForWriting(const std::string& dir, const std::string& what,
                              const std::string& source, const std::string& field);
// Same with the lock file `path` instead: for a command whose folder's .handlabel.lock
// belongs to a job it runs inside it (`adapt` locks <out>/adapt.lock).
FileLock LockFolderForWriting(const std::string& dir, const std::string& path,
                              const std::string& what, const std::string& source,
                              const std::string& field);

}  // namespace handlabel
