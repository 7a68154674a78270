// One writer per output folder, with real processes of the built binary: a second
// `label` of the same shard and a `merge` during a run are refused naming the holder;
// a lock left by kill -9 does not block; shards of one job still run in parallel.

#include <signal.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "pipeline/frame_log.h"
#include "pipeline/label_outputs.h"
#include "pipeline/output_lock.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::SpawnHandlabel;
using testing::WaitForExit;
using testing::WaitUntilHolding;

int OkFrames(const std::string& out) {
  int ok = 0;
  for (const auto& [frame, record] : ReadShardLogs(out)) ok += record.status == "ok";
  return ok;
}

TEST(OutputLockCommand, SecondLabelAndMergeAreRefusedWhileARunHoldsTheFolder) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 4, 5);
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  const pid_t first = SpawnHandlabel({"label", "--job", job}, dir + "/first.log");
  ASSERT_TRUE(WaitUntilHolding(first, ShardLockPath(dir + "/out", {0, 1})))
      << testing::ReadFileBytes(dir + "/first.log");
  kill(first, SIGSTOP);  // keeps the lock while the others try
  const std::string holder = "pid " + std::to_string(first);
  EXPECT_EQ(WaitForExit(SpawnHandlabel({"label", "--job", job}, dir + "/second.log")), 1);
  const std::string second = testing::ReadFileBytes(dir + "/second.log");
  EXPECT_THAT(second, HasSubstr(job));
  EXPECT_THAT(second, HasSubstr("shard 0/1"));
  EXPECT_THAT(second, HasSubstr(holder));
  EXPECT_THAT(second, HasSubstr("on host"));
  EXPECT_EQ(WaitForExit(SpawnHandlabel({"merge", "--job", job}, dir + "/merge.log")), 1);
  EXPECT_THAT(testing::ReadFileBytes(dir + "/merge.log"), HasSubstr(holder));
  kill(first, SIGCONT);
  EXPECT_EQ(WaitForExit(first), 0) << testing::ReadFileBytes(dir + "/first.log");
  EXPECT_EQ(OkFrames(dir + "/out"), 4);  // one record per frame: nothing twice
  EXPECT_EQ(FrameLog::Read(ShardLogPath(dir + "/out", {0, 1})).size(), 4u);
}

TEST(OutputLockCommand, LockOfAKilledRunDoesNotBlockTheResume) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 4, 6);
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  const pid_t killed = SpawnHandlabel({"label", "--job", job}, dir + "/killed.log");
  ASSERT_TRUE(WaitUntilHolding(killed, ShardLockPath(dir + "/out", {0, 1})));
  kill(killed, SIGKILL);
  EXPECT_EQ(WaitForExit(killed), -SIGKILL);
  EXPECT_EQ(
      WaitForExit(SpawnHandlabel({"label", "--job", job, "--resume"}, dir + "/r.log")), 0)
      << testing::ReadFileBytes(dir + "/r.log");
  EXPECT_EQ(OkFrames(dir + "/out"), 4);
}

TEST(OutputLockCommand, ShardsOfOneJobRunInParallel) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 6, 7);
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  std::vector<pid_t> shards;
  for (int i = 0; i < 3; ++i) {
    shards.push_back(
        SpawnHandlabel({"label", "--job", job, "--shard", std::to_string(i) + "/3"},
                       dir + "/shard" + std::to_string(i) + ".log"));
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(WaitForExit(shards[i]), 0)
        << testing::ReadFileBytes(dir + "/shard" + std::to_string(i) + ".log");
  }
  EXPECT_EQ(WaitForExit(SpawnHandlabel({"merge", "--job", job}, dir + "/merge.log")), 0)
      << testing::ReadFileBytes(dir + "/merge.log");
  EXPECT_EQ(OkFrames(dir + "/out"), 6);
}

}  // namespace
}  // namespace handlabel
