#pragma once
// One writer per output folder. Advisory locks (flock) on files in the folder, which
// the kernel releases when the holder dies, so a lock left by kill -9 never blocks the
// next run (the file stays, with its last holder's details, and is simply locked
// again):
//   <output.dir>/.handlabel.lock                  the folder: shared by every `label`
//                                                 shard, exclusive for `merge` and
//                                                 for rewriting job.json (--force)
//   <output.dir>/shards/shard-<i>-of-<N>.lock     one shard: exclusive for its run
// Shards of one job therefore run in parallel (each locks its own shard), while the
// same shard twice, `merge` during a run, or another job's --force during a run are
// refused with an InputError naming the holders' pid, host and start time.

#include <string>
#include <vector>

#include "pipeline/shard.h"

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

std::string FolderLockPath(const std::string& output_dir);
std::string ShardLockPath(const std::string& output_dir, const ShardSpec& shard);

// The locks of one writer of an output folder.
class OutputFolderLock {
 public:
  OutputFolderLock() = default;  // holds nothing
  // A `label` run of one shard: the folder shared, the shard exclusive. `source` (the
  // job file) is named in errors.
  static OutputFolderLock ForShard(const std::string& output_dir, const ShardSpec& shard,
                                   const std::string& source);
  // `merge` (or anything rewriting the whole folder): the folder exclusive.
  static OutputFolderLock Whole(const std::string& output_dir, const std::string& command,
                                const std::string& source);
  // Upgrades a shard run's folder lock to exclusive (before job.json is replaced).
  // Throws InputError naming the other holders when other runs use the folder.
  void MakeWhole(const std::string& why);

 private:
  // "shard 0/2: label, pid 123 on host h since ...; ..." for every running holder.
  static std::string DescribeHolders(const std::string& output_dir);

  std::string output_dir_;
  std::string source_;
  FileLock folder_;
  FileLock shard_;
};

}  // namespace handlabel
