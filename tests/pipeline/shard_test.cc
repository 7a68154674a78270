#include "pipeline/shard.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "core/errors.h"

namespace handlabel {
namespace {

std::vector<std::string> Frames(int n) {
  std::vector<std::string> frames;
  for (int i = 0; i < n; ++i) frames.push_back("f" + std::to_string(1000 + i));
  return frames;
}

TEST(Shard, EveryFrameLandsInExactlyOneShardInOrder) {
  for (int n : {0, 1, 7, 100, 101}) {
    for (int count : {1, 2, 3, 8, 150}) {
      const auto all = Frames(n);
      std::vector<std::string> joined;
      for (int i = 0; i < count; ++i) {
        const auto part = FramesOfShard(all, {i, count});
        // Balanced: sizes differ by at most one.
        EXPECT_LE(part.size(), static_cast<size_t>(n / count + 1));
        EXPECT_GE(part.size(), static_cast<size_t>(n / count));
        joined.insert(joined.end(), part.begin(), part.end());
      }
      EXPECT_EQ(joined, all) << n << " frames over " << count;
    }
  }
}

TEST(Shard, ParseAcceptsValidAndRejectsInvalidSpecs) {
  const ShardSpec s = ParseShard("3/16");
  EXPECT_EQ(s.index, 3);
  EXPECT_EQ(s.count, 16);
  EXPECT_EQ(s.ToString(), "3/16");
  for (const char* bad : {"16/16", "-1/4", "1/0", "a/b", "3", "3/", "/3", "1/2/3", ""}) {
    EXPECT_THROW(ParseShard(bad), InputError) << bad;
  }
}

std::map<std::string, std::string> g_env;
const char* FakeGetenv(const char* name) {
  const auto it = g_env.find(name);
  return it == g_env.end() ? nullptr : it->second.c_str();
}

TEST(Shard, EnvironmentOfSlurmArraysAndKubernetesIndexedJobs) {
  g_env = {};
  EXPECT_FALSE(ShardFromEnvironment(FakeGetenv).has_value());
  g_env = {{"SLURM_ARRAY_TASK_ID", "5"}, {"SLURM_ARRAY_TASK_COUNT", "8"}};
  EXPECT_EQ(ShardFromEnvironment(FakeGetenv)->ToString(), "5/8");
  g_env = {{"JOB_COMPLETION_INDEX", "2"}, {"HANDLABEL_SHARD_COUNT", "4"}};
  EXPECT_EQ(ShardFromEnvironment(FakeGetenv)->ToString(), "2/4");
  g_env = {{"SLURM_ARRAY_TASK_ID", "5"}};
  EXPECT_THROW(ShardFromEnvironment(FakeGetenv), InputError);
  g_env = {{"JOB_COMPLETION_INDEX", "2"}};
  EXPECT_THROW(ShardFromEnvironment(FakeGetenv), InputError);
  g_env = {{"SLURM_ARRAY_TASK_ID", "9"}, {"SLURM_ARRAY_TASK_COUNT", "8"}};
  EXPECT_THROW(ShardFromEnvironment(FakeGetenv), InputError);
}

}  // namespace
}  // namespace handlabel
