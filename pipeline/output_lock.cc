#include "pipeline/output_lock.h"

#include <algorithm>
#include <filesystem>

#include "core/errors.h"
#include "pipeline/label_outputs.h"

namespace handlabel {

namespace fs = std::filesystem;

std::string ShardLockPath(const std::string& output_dir, const ShardSpec& shard) {
  const std::string log = ShardLogPath(output_dir, shard);
  return log.substr(0, log.size() - std::string(".jsonl").size()) + ".lock";
}

std::string SmoothingLockPath(const std::string& output_dir, const ShardSpec& shard) {
  return output_dir + "/smoothed/" +
         fs::path(ShardLockPath(output_dir, shard)).filename().string();
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
  std::vector<std::string> locks;
  for (const char* folder : {"shards", "smoothed"}) {
    for (const auto& e : fs::directory_iterator(fs::path(output_dir) / folder, ignored)) {
      if (e.path().extension() == ".lock") locks.push_back(e.path().string());
    }
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
  return ForPartOfFolder(output_dir, ShardLockPath(output_dir, shard),
                         "label shard " + shard.ToString(), source);
}

OutputFolderLock OutputFolderLock::ForSmoothing(const std::string& output_dir,
                                                const ShardSpec& shard,
                                                const std::string& source) {
  return ForPartOfFolder(output_dir, SmoothingLockPath(output_dir, shard),
                         "smooth shard " + shard.ToString(), source);
}

OutputFolderLock OutputFolderLock::ForPartOfFolder(const std::string& output_dir,
                                                   const std::string& shard_lock,
                                                   const std::string& what,
                                                   const std::string& source) {
  fs::create_directories(fs::path(shard_lock).parent_path());
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
  lock.shard_ = FileLock::TryAcquire(shard_lock, FileLock::Mode::kExclusive);
  if (!lock.shard_.held()) {
    throw InputError(source, "output.dir",
                     "no other process running " + what + " of " + output_dir,
                     "held by " + ReadLockHolder(shard_lock));
  }
  lock.shard_.RecordHolder(what);
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
