#pragma once
// One writer per label output folder, with the advisory locks of core/file_lock.h
// (released by the kernel when the holder dies):
//   <output.dir>/.handlabel.lock                  the folder: shared by every `label`
//                                                 shard, exclusive for `merge` and
//                                                 for rewriting job.json (--force)
//   <output.dir>/shards/shard-<i>-of-<N>.lock     one shard: exclusive for its run
//   <output.dir>/smoothed/shard-<i>-of-<N>.lock   one shard's smoothing pass
//                                                 (`smooth`, the folder shared)
// Shards of one job therefore run in parallel (each locks its own shard), while the
// same shard twice, `merge` during a run, or another job's --force during a run or a
// smoothing pass are refused with an InputError naming the holders' pid, host and
// start time.

#include <string>
#include <vector>

#include "core/file_lock.h"
#include "pipeline/shard.h"

namespace handlabel {

std::string ShardLockPath(const std::string& output_dir, const ShardSpec& shard);
std::string SmoothingLockPath(const std::string& output_dir, const ShardSpec& shard);

// The locks of one writer of an output folder.
class OutputFolderLock {
 public:
  OutputFolderLock() = default;  // holds nothing
  // A `label` run of one shard: the folder shared, the shard exclusive. `source` (the
  // job file) is named in errors.
  static OutputFolderLock ForShard(const std::string& output_dir, const ShardSpec& shard,
                                   const std::string& source);
  // A smoothing pass of one shard (pipeline/smooth_job.h): the folder shared (the
  // per-frame labels it reads cannot be replaced by a --force run meanwhile), its
  // shard's smoothing exclusive.
  static OutputFolderLock ForSmoothing(const std::string& output_dir,
                                       const ShardSpec& shard, const std::string& source);
  // `merge` (or anything rewriting the whole folder): the folder exclusive.
  static OutputFolderLock Whole(const std::string& output_dir, const std::string& command,
                                const std::string& source);
  // Upgrades a shard run's folder lock to exclusive (before job.json is replaced).
  // Throws InputError naming the other holders when other runs use the folder.
  void MakeWhole(const std::string& why);

 private:
  // The folder shared and `shard_lock` (a shard's label run or smoothing) exclusive.
  static OutputFolderLock ForPartOfFolder(const std::string& output_dir,
                                          const std::string& shard_lock,
                                          const std::string& what,
                                          const std::string& source);
  // "shard 0/2: label, pid 123 on host h since ...; ..." for every running holder.
  static std::string DescribeHolders(const std::string& output_dir);

  std::string output_dir_;
  std::string source_;
  FileLock folder_;
  FileLock shard_;
};

}  // namespace handlabel
