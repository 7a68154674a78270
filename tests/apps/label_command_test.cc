// End-to-end tests of `handlabel label` / `handlabel merge` on a synthetic capture with
// the real fitter: kill -9 at random moments and resume, shards and merge, usage.

#include <signal.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "pipeline/frame_log.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_record.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

using testing::SpawnHandlabel;
using testing::WaitForExit;

// Nothing half-written: every label on disk parses completely, every mesh has all
// its vertex and face lines, and every frame the log calls finished has its label.
void ExpectConsistent(const std::string& out) {
  if (fs::is_directory(out + "/labels")) {
    for (const auto& e : fs::directory_iterator(out + "/labels")) {
      const std::string name = e.path().filename().string();
      if (name.find(".tmp.") != std::string::npos) continue;  // never a final name
      EXPECT_NO_THROW(ReadLabelFile(e.path().string())) << name;
    }
  }
  if (fs::is_directory(out + "/meshes")) {
    for (const auto& e : fs::directory_iterator(out + "/meshes")) {
      if (e.path().filename().string().find(".tmp.") != std::string::npos) continue;
      const std::string text = testing::ReadFileBytes(e.path().string());
      EXPECT_EQ(text.back(), '\n') << e.path();
      EXPECT_THAT(text, HasSubstr("end_header")) << e.path();
    }
  }
  for (const auto& [frame, record] : ReadShardLogs(out)) {
    if (record.status == "ok") {
      EXPECT_TRUE(fs::exists(LabelFilePath(out, frame))) << frame;
    }
  }
}

int FinishedFrames(const std::string& out) {
  int done = 0;
  for (const auto& [frame, record] : ReadShardLogs(out)) done += record.status == "ok";
  return done;
}

TEST(LabelCommand,
     KillNineAtRandomMomentsLosesNoFinishedFrameAndResumesToIdenticalLabels) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 8, 21);
  const std::string reference_job =
      testing::WriteTestJob(dir, "reference", "capture", "ref");
  const std::string killed_job =
      testing::WriteTestJob(dir, "killed", "capture", "killed");

  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(
      WaitForExit(SpawnHandlabel({"label", "--job", reference_job}, dir + "/ref.log")), 0)
      << testing::ReadFileBytes(dir + "/ref.log");
  const double full_run_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // HANDLABEL_KILL_ROUNDS=N runs more kill points (the default keeps ctest quick).
  const char* rounds_env = std::getenv("HANDLABEL_KILL_ROUNDS");
  const int rounds = rounds_env ? std::atoi(rounds_env) : 3;
  int finished_before = 0, killed_mid_run = 0;
  for (int round = 0; round < rounds; ++round) {
    const pid_t pid =
        SpawnHandlabel({"label", "--job", killed_job, "--resume"}, dir + "/killed.log");
    // Round 0 kills well inside the run's time, so at least one kill lands mid-run.
    const double kill_after_s = round == 0 ? testing::Uniform(0.2, 0.6) * full_run_s
                                           : testing::Uniform(0.0, full_run_s);
    std::this_thread::sleep_for(std::chrono::duration<double>(kill_after_s));
    kill(pid, SIGKILL);
    killed_mid_run += WaitForExit(pid) == -SIGKILL;
    ExpectConsistent(dir + "/killed");
    const int finished = FinishedFrames(dir + "/killed");
    EXPECT_GE(finished, finished_before)
        << "a finished frame was lost in round " << round;
    finished_before = finished;
  }
  ASSERT_EQ(WaitForExit(SpawnHandlabel({"label", "--job", killed_job, "--resume"},
                                       dir + "/killed.log")),
            0)
      << testing::ReadFileBytes(dir + "/killed.log");
  RecordProperty("kill_rounds", rounds);
  RecordProperty("killed_mid_run", killed_mid_run);
  EXPECT_GE(killed_mid_run, 1);

  // Identical outputs, and no temporary left behind.
  const auto reference = testing::FilesUnder(dir + "/ref/labels");
  const auto resumed = testing::FilesUnder(dir + "/killed/labels");
  ASSERT_EQ(reference.size(), 8u);
  EXPECT_EQ(resumed, reference);
  EXPECT_EQ(testing::FilesUnder(dir + "/killed/meshes"),
            testing::FilesUnder(dir + "/ref/meshes"));
  EXPECT_EQ(testing::ReadFileBytes(dir + "/killed/manifest.json"),
            testing::ReadFileBytes(dir + "/ref/manifest.json"));
}

TEST(LabelCommand, ShardsFromFlagOrEnvironmentMergeToTheSingleProcessResult) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 5, 8);
  const std::string single = testing::WriteTestJob(dir, "single", "capture", "single");
  const std::string sharded = testing::WriteTestJob(dir, "sharded", "capture", "sharded");
  ASSERT_EQ(RunHandlabelCommand({"label", "--job", single, "--quiet"}).status, 0);

  ASSERT_EQ(RunHandlabelCommand({"label", "--job", sharded, "--shard", "2/3", "--quiet"})
                .status,
            0);
  const auto early = RunHandlabelCommand({"merge", "--job", sharded});
  EXPECT_EQ(early.status, 1);  // shards 0 and 1 have not run
  EXPECT_THAT(early.out, HasSubstr("not yet run"));

  setenv("SLURM_ARRAY_TASK_ID", "0", 1);
  setenv("SLURM_ARRAY_TASK_COUNT", "3", 1);
  const auto from_env = RunHandlabelCommand({"label", "--job", sharded});
  unsetenv("SLURM_ARRAY_TASK_ID");
  unsetenv("SLURM_ARRAY_TASK_COUNT");
  ASSERT_EQ(from_env.status, 0) << from_env.err;
  EXPECT_THAT(from_env.err, HasSubstr("shard 0/3"));
  setenv("JOB_COMPLETION_INDEX", "1", 1);
  setenv("HANDLABEL_SHARD_COUNT", "3", 1);
  const auto from_k8s = RunHandlabelCommand({"label", "--job", sharded, "--quiet"});
  unsetenv("JOB_COMPLETION_INDEX");
  unsetenv("HANDLABEL_SHARD_COUNT");
  ASSERT_EQ(from_k8s.status, 0) << from_k8s.err;

  const auto merged = RunHandlabelCommand({"merge", "--job", sharded});
  ASSERT_EQ(merged.status, 0) << merged.err;
  EXPECT_THAT(merged.out, HasSubstr("5 frames: 5 labelled"));
  // merge states where the 2D came from, as the shards did.
  EXPECT_THAT(merged.out, HasSubstr("2D keypoints: "));
  EXPECT_THAT(testing::ReadFileBytes(dir + "/sharded/summary.md"),
              HasSubstr("2D keypoints: "));
  // The merge knows no wall time (shards may run anywhere: no zero written), but the
  // shards' stage times summed over every frame.
  const nlohmann::json merged_summary =
      nlohmann::json::parse(testing::ReadFileBytes(dir + "/sharded/summary.json"));
  EXPECT_FALSE(merged_summary.contains("wall_seconds"));
  EXPECT_EQ(merged_summary.at("stage_frames").get<int>(), 5);
  EXPECT_EQ(testing::FilesUnder(dir + "/sharded/labels"),
            testing::FilesUnder(dir + "/single/labels"));
  EXPECT_EQ(testing::ReadFileBytes(dir + "/sharded/manifest.json"),
            testing::ReadFileBytes(dir + "/single/manifest.json"));
  // Three shard logs, each frame in exactly one of them.
  int records = 0;
  for (int i = 0; i < 3; ++i) {
    records += FrameLog::Read(ShardLogPath(dir + "/sharded", {i, 3})).size();
  }
  EXPECT_EQ(records, 5);
}

TEST(LabelCommand, FitOnlyJobLabelsEveryFrameCloseToTheGroundTruth) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 3, 5);
  const std::string job = testing::WriteTestJob(dir, "fit", "capture", "out");
  const auto r = RunHandlabelCommand({"label", "--job", job});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("3 frames: 3 labelled (fallback_fit 3), 0 failed"));
  const nlohmann::json summary =
      nlohmann::json::parse(testing::ReadFileBytes(dir + "/out/summary.json"));
  // Simulated detections with ~2 px noise at 160x120: the fit lands within ~1.5 cm.
  EXPECT_LT(summary.at("metrics").at("labels").at("mpjpe_mm").get<double>(), 15.0);
  // A run of the whole job merges at its end: its wall time and threads go into
  // summary.json, as into its shard's summary, beside the stage times.
  const nlohmann::json shard = nlohmann::json::parse(
      testing::ReadFileBytes(dir + "/out/shards/shard-00000-of-00001.summary.json"));
  EXPECT_GT(shard.at("wall_seconds").get<double>(), 0.0);
  EXPECT_EQ(summary.at("wall_seconds"), shard.at("wall_seconds"));
  EXPECT_EQ(summary.at("threads"), shard.at("threads"));
  EXPECT_EQ(summary.at("stage_frames").get<int>(), 3);
  EXPECT_THAT(r.err, HasSubstr("where the time went (3 frames"));
  const LabelRecord label = ReadLabelFile(LabelFilePath(dir + "/out", "000001"));
  EXPECT_EQ(label.path, LabelPath::kFallbackFit);
  ASSERT_TRUE(label.params.has_value());
  EXPECT_EQ(label.provenance.hand_model, "capsule_hand_right");
  EXPECT_EQ(label.fit.at("init"), "triangulated_views");
}

TEST(LabelCommand, UsageAndJobErrors) {
  const std::string dir = testing::ScratchDir();
  EXPECT_EQ(RunHandlabelCommand({"label"}).status, 2);
  const auto both =
      RunHandlabelCommand({"label", "--job", "x.yaml", "--resume", "--force"});
  EXPECT_EQ(both.status, 2);
  const auto missing = RunHandlabelCommand({"label", "--job", dir + "/nope.yaml"});
  EXPECT_EQ(missing.status, 1);
  EXPECT_THAT(missing.err, HasSubstr("nope.yaml"));
  const auto bad_shard =
      RunHandlabelCommand({"label", "--job", dir + "/nope.yaml", "--shard", "3/3"});
  EXPECT_EQ(bad_shard.status, 1);
  EXPECT_TRUE(RunHandlabelCommand({"label", "--help"}).out.find("--shard") !=
              std::string::npos);
  EXPECT_TRUE(RunHandlabelCommand({"merge", "--help"}).out.find("--job") !=
              std::string::npos);
}

}  // namespace
}  // namespace handlabel
