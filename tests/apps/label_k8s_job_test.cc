// The Kubernetes Indexed Job of jobs/k8s run as its pods run it: each pod is the
// container's command and environment read from the YAML, with JOB_COMPLETION_INDEX set
// as Kubernetes sets it and only the image's paths replaced by the test's (`handlabel`
// by the built binary, the job file by a test job). Its schema is checked by the CTest
// k8s_job_files (tools/k8s/check-jobs.mjs).

#include <yaml-cpp/yaml.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/frame_log.h"
#include "pipeline/label_outputs.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::RunHandlabelCommand;
using testing::SpawnHandlabel;
using testing::WaitForExit;

using Environment = std::vector<std::pair<std::string, std::string>>;

// What a pod of the Indexed Job runs.
struct IndexedJobPod {
  int completions = 0;
  int parallelism = 0;
  std::vector<std::string> command;  // as written, command[0] = "handlabel"
  Environment env;                   // the container's env, as written
};

IndexedJobPod ReadIndexedJob(const std::string& path) {
  const YAML::Node job = YAML::LoadFile(path);
  const YAML::Node spec = job["spec"];
  IndexedJobPod pod;
  pod.completions = spec["completions"].as<int>();
  pod.parallelism = spec["parallelism"].as<int>();
  const YAML::Node container = spec["template"]["spec"]["containers"][0];
  for (const auto& word : container["command"])
    pod.command.push_back(word.as<std::string>());
  for (const auto& e : container["env"]) {
    pod.env.emplace_back(e["name"].as<std::string>(), e["value"].as<std::string>());
  }
  return pod;
}

// The command's arguments after `handlabel`, with the job file (the word after --job)
// replaced by `job`.
std::vector<std::string> PodArguments(const IndexedJobPod& pod, const std::string& job) {
  std::vector<std::string> args(pod.command.begin() + 1, pod.command.end());
  for (size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == "--job") args[i + 1] = job;
  }
  return args;
}

TEST(LabelK8sJob, IndexedPodsLabelDisjointShardsThatCoverTheJobAndRetriesResume) {
  const IndexedJobPod pod = ReadIndexedJob(std::string(HANDLABEL_SOURCE_DIR) +
                                           "/jobs/k8s/label-indexed-job.yaml");
  ASSERT_GE(pod.command.size(), 2u);
  ASSERT_EQ(pod.command[0], "handlabel");
  ASSERT_EQ(pod.command[1], "label");
  ASSERT_THAT(pod.env,
              ::testing::Contains(std::make_pair(std::string("HANDLABEL_SHARD_COUNT"),
                                                 std::to_string(pod.completions))));
  ASSERT_GE(pod.completions, 2);

  const std::string dir = testing::ScratchDir();
  const int frames = pod.completions + 4;  // every shard gets one or two frames
  testing::WriteTestCapture(dir + "/capture", frames, 17);
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  const std::vector<std::string> args = PodArguments(pod, job);

  // Indices 0 .. completions-1, as the Job runs them; at most two pods at a time (the
  // Job's `parallelism` changes only how many run at once; CI machines have 2 cores).
  const int at_once = std::min(pod.parallelism, 2);
  auto pod_env = [&](int index) {
    Environment env = pod.env;
    env.emplace_back("JOB_COMPLETION_INDEX", std::to_string(index));
    return env;
  };
  auto log_of = [&](int index) { return dir + "/pod-" + std::to_string(index) + ".log"; };
  std::vector<std::pair<int, pid_t>> running;
  std::string failures;
  auto wait_for_first = [&] {
    const auto [index, pid] = running.front();
    running.erase(running.begin());
    if (WaitForExit(pid) != 0) failures += testing::ReadFileBytes(log_of(index));
  };
  for (int index = 0; index < pod.completions; ++index) {
    if (static_cast<int>(running.size()) == at_once) wait_for_first();
    running.emplace_back(index, SpawnHandlabel(args, log_of(index), 0, pod_env(index)));
  }
  while (!running.empty()) wait_for_first();
  ASSERT_EQ(failures, "");

  // Each pod labelled its own shard: the shards' frames are disjoint and cover the job.
  const std::string count = "/" + std::to_string(pod.completions);
  std::set<std::string> labelled;
  size_t records = 0;
  for (int index = 0; index < pod.completions; ++index) {
    EXPECT_THAT(testing::ReadFileBytes(log_of(index)),
                HasSubstr("shard " + std::to_string(index) + count));
    const auto log = FrameLog::Read(ShardLogPath(dir + "/out", {index, pod.completions}));
    EXPECT_FALSE(log.empty()) << "pod " << index;
    for (const auto& record : log) {
      EXPECT_EQ(record.status, "ok") << record.frame << ": " << record.reason;
      labelled.insert(record.frame);
    }
    records += log.size();
  }
  EXPECT_EQ(records, labelled.size()) << "a frame was labelled by two pods";
  EXPECT_EQ(labelled.size(), static_cast<size_t>(frames));

  // A pod retried with the same index (backoffLimitPerIndex) resumes: nothing redone.
  const std::string shard_log = ShardLogPath(dir + "/out", {1, pod.completions});
  const std::string before = testing::ReadFileBytes(shard_log);
  EXPECT_EQ(WaitForExit(SpawnHandlabel(args, log_of(100), 0, pod_env(1))), 0)
      << testing::ReadFileBytes(log_of(100));
  EXPECT_EQ(testing::ReadFileBytes(shard_log), before);

  // The merge the YAML's comment says to run afterwards.
  const auto merged = RunHandlabelCommand({"merge", "--job", job});
  ASSERT_EQ(merged.status, 0) << merged.out << merged.err;
  EXPECT_THAT(merged.out, HasSubstr(std::to_string(frames) +
                                    " frames: " + std::to_string(frames) + " labelled"));
}

}  // namespace
}  // namespace handlabel
