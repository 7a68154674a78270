#include "pipeline/output_lock.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

// flock locks belong to open file descriptions, so two locks taken by one process
// through separate opens conflict exactly as two processes' locks do.
TEST(OutputLock, ShardsOfOneFolderLockTheirOwnShardOnly) {
  const std::string out = testing::ScratchDir() + "/out";
  const OutputFolderLock a = OutputFolderLock::ForShard(out, {0, 2}, "a.yaml");
  const OutputFolderLock b = OutputFolderLock::ForShard(out, {1, 2}, "b.yaml");
  const std::string error = testing::InputErrorOf([&] {
    OutputFolderLock::ForShard(out, {1, 2}, "c.yaml");
  });
  EXPECT_THAT(error, HasSubstr("c.yaml"));
  EXPECT_THAT(error, HasSubstr("shard 1/2"));
  EXPECT_THAT(error, HasSubstr("pid " + std::to_string(::getpid())));
  EXPECT_THAT(error, HasSubstr("on host "));
  // merge needs the whole folder: both running shards are named.
  const std::string merge_error =
      testing::InputErrorOf([&] { OutputFolderLock::Whole(out, "merge", "m.yaml"); });
  EXPECT_THAT(merge_error, HasSubstr("label shard 0/2"));
  EXPECT_THAT(merge_error, HasSubstr("label shard 1/2"));
}

// A smoothing pass locks its shard's smoothing and shares the folder: beside a label
// run and another shard's smoothing, never twice the same shard, never with a merge.
TEST(OutputLock, SmoothingLocksItsShardAndSharesTheFolder) {
  const std::string out = testing::ScratchDir() + "/out";
  const OutputFolderLock smoothing =
      OutputFolderLock::ForSmoothing(out, {0, 2}, "s.yaml");
  EXPECT_NO_THROW(OutputFolderLock::ForSmoothing(out, {1, 2}, "t.yaml"));
  EXPECT_NO_THROW(OutputFolderLock::ForShard(out, {0, 2}, "j.yaml"));
  const std::string error = testing::InputErrorOf([&] {
    OutputFolderLock::ForSmoothing(out, {0, 2}, "u.yaml");
  });
  EXPECT_THAT(error, HasSubstr("u.yaml"));
  EXPECT_THAT(error,
              HasSubstr("held by smooth shard 0/2, pid " + std::to_string(::getpid())));
  const std::string merge_error =
      testing::InputErrorOf([&] { OutputFolderLock::Whole(out, "merge", "m.yaml"); });
  EXPECT_THAT(merge_error, HasSubstr("smooth shard 0/2"));
}

TEST(OutputLock, MergeKeepsLabelOutAndRecordsItself) {
  const std::string out = testing::ScratchDir() + "/out";
  {
    const OutputFolderLock merge = OutputFolderLock::Whole(out, "merge", "m.yaml");
    const std::string error = testing::InputErrorOf([&] {
      OutputFolderLock::ForShard(out, {0, 1}, "j.yaml");
    });
    EXPECT_THAT(error, HasSubstr("j.yaml"));
    EXPECT_THAT(error, HasSubstr("in use by merge, pid " + std::to_string(::getpid())));
  }
  EXPECT_NO_THROW(OutputFolderLock::ForShard(out, {0, 1}, "j.yaml"));  // released
}

TEST(OutputLock, UpgradeToWholeFolderOnlyWhenAlone) {
  const std::string out = testing::ScratchDir() + "/out";
  OutputFolderLock alone = OutputFolderLock::ForShard(out, {0, 1}, "a.yaml");
  EXPECT_NO_THROW(alone.MakeWhole("replace job.json"));
  alone = OutputFolderLock();
  OutputFolderLock first = OutputFolderLock::ForShard(out, {0, 2}, "a.yaml");
  OutputFolderLock second = OutputFolderLock::ForShard(out, {1, 2}, "b.yaml");
  const std::string error =
      testing::InputErrorOf([&] { second.MakeWhole("replace job.json"); });
  EXPECT_THAT(error, HasSubstr("b.yaml"));
  EXPECT_THAT(error, HasSubstr("label shard 0/2"));
}

// A holder killed with SIGKILL leaves its lock file, but the kernel has released the
// flock: the next writer gets the folder.
TEST(OutputLock, LockOfAKilledProcessDoesNotBlock) {
  const std::string out = testing::ScratchDir() + "/out";
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  if (child == 0) {
    const OutputFolderLock held = OutputFolderLock::ForShard(out, {0, 1}, "child.yaml");
    const char byte = 1;
    if (write(ready[1], &byte, 1) != 1) _exit(2);
    pause();
    _exit(0);
  }
  char byte = 0;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);
  const std::string error = testing::InputErrorOf([&] {
    OutputFolderLock::ForShard(out, {0, 1}, "j.yaml");
  });
  EXPECT_THAT(error, HasSubstr("pid " + std::to_string(child)));
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(fs::exists(ShardLockPath(out, {0, 1})));
  EXPECT_NO_THROW(OutputFolderLock::ForShard(out, {0, 1}, "j.yaml"));
  close(ready[0]);
  close(ready[1]);
}

}  // namespace
}  // namespace handlabel
