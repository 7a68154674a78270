// `handlabel adapt` end to end on a tiny network and a small synthetic capture: every
// stage runs and leaves its files, a second run continues instead of redoing, the
// exported weights are the same when made again, and a folder holding another run is
// refused by name (the plumbing, not the accuracy, is under test: docs/adapt.md has
// the measured numbers).

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "core/json_util.h"
#include "image/image.h"
#include "pipeline/job_config.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// Starting weights: a tiny 8-view network after two steps on synthetic frames.
std::string TinyWeights(const std::string& dir) {
  const std::string config = dir + "/tiny.yaml";
  std::ofstream(config) << "network: tiny\nhand_model: \"\"\n"
                        << "data: {preset: dexycb, width: 320, height: 240, seed: 4}\n"
                        << "train:\n  steps: 2\n  batch_size: 1\n  warmup_steps: 1\n"
                        << "  checkpoint_every: 1\n  log_every: 1\n  validate_every: 0\n"
                        << "  prefetch_batches: 0\n  out_dir: " << dir << "/tiny\n";
  EXPECT_EQ(RunHandlabelCommand({"train", "--config", config}).status, 0);
  const auto exported =
      RunHandlabelCommand({"train", "--config", config, "--export", dir + "/tiny.pt"});
  EXPECT_EQ(exported.status, 0) << exported.err;
  return dir + "/tiny.pt";
}

// A 6-frame synthetic capture with the simulated detector's 2D (the open hand, so the
// fit labels have the network's 778 vertices).
std::string SmallCapture(const std::string& dir) {
  const std::string capture = dir + "/capture";
  const auto synth =
      RunHandlabelCommand({"synth", "--preset", "dexycb", "--frames", "6", "--seed", "3",
                           "--size", "160x120", "--threads", "1", "--out", capture});
  EXPECT_EQ(synth.status, 0) << synth.err;
  return capture;
}

const char* const kStages[] = {"detect", "fit",     "backgrounds", "train",
                               "export", "heldout", "label"};

TEST(AdaptCommand, RunsEveryStageContinuesAndRefusesAnotherRunsFolder) {
  const std::string dir = testing::ScratchDir();
  const std::string weights = TinyWeights(dir), capture = SmallCapture(dir);
  const std::string out = dir + "/adapted";
  const std::vector<std::string> command = {
      "adapt", "--capture",     capture,         "--out",     out, "--weights",
      weights, "--budget",      "0.01",          "--threads", "1", "--heldout",
      "4:6",   "--no-overlays", "--synth-share", "0.5"};
  const auto first = RunHandlabelCommand(command);
  ASSERT_EQ(first.status, 0) << first.err;
  for (const char* stage : kStages) {
    EXPECT_TRUE(fs::exists(out + "/stages/" + stage + ".done")) << stage;
  }
  EXPECT_THAT(first.err, HasSubstr("the capture has detections"));
  // Synthetic hands in the capture's look: one background per camera, of its size,
  // and the picture of what training saw.
  for (int c = 0; c < 8; ++c) {
    const std::string path = out + "/backgrounds/cam0" + std::to_string(c) + ".png";
    ASSERT_TRUE(fs::exists(path)) << path;
    const ImageU8 background = ReadPng(path);
    EXPECT_EQ(background.width, 160);
    EXPECT_EQ(background.height, 120);
  }
  EXPECT_TRUE(fs::exists(out + "/train/samples.jpg"));
  // A budget too small for training gets the fewest steps, and says so.
  const nlohmann::json plan = ReadJsonFileStrict(out + "/train/plan.json");
  EXPECT_EQ(plan["steps"], 40);
  EXPECT_EQ(plan["budget_too_small"], true);
  const nlohmann::json card = ReadJsonFileStrict(out + "/model_card.json");
  EXPECT_EQ(card["training_frames"], 4);  // the held-out frames never train
  EXPECT_EQ(card["heldout_frames"].size(), 2u);
  EXPECT_EQ(card["heldout"]["before"]["frames"], 2);
  EXPECT_EQ(card["heldout"]["after"]["frames"], 2);
  EXPECT_GT(card["heldout"]["after"]["mpjpe_mm_vs_fit_labels"].get<double>(), 0);
  int labelled = 0;
  for (const auto& [path, count] : card["labels_by_path"].items())
    labelled += count.get<int>();
  EXPECT_EQ(labelled, 6);
  int fit_labels = 0;
  for (const auto& entry : fs::directory_iterator(out + "/fit/labels")) {
    fit_labels += entry.path().extension() == ".json";
  }
  EXPECT_EQ(fit_labels, 6);
  EXPECT_TRUE(fs::exists(out + "/model_card.md"));
  // The label stage checks the answers with the thresholds chosen on the held-out ones.
  const nlohmann::json chosen =
      ReadJsonFileStrict(out + "/heldout/heldout.json")["thresholds"]["refine"];
  const std::map<std::string, std::string> field_of_check = {
      {"reprojection", "max_reprojection_px"},
      {"view_agreement", "max_view_disagreement_mm"},
      {"detector_agreement", "max_detector_rms_px"}};
  int compared = 0;
  for (const auto& entry : fs::directory_iterator(out + "/labels")) {
    const nlohmann::json label = ReadJsonFileStrict(entry.path().string());
    for (const nlohmann::json& check : label["quality"]["checks"]) {
      const auto field = field_of_check.find(check["name"].get<std::string>());
      if (field == field_of_check.end()) continue;
      EXPECT_DOUBLE_EQ(check["threshold"].get<double>(),
                       chosen[field->second].get<double>())
          << field->first;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 3 * 6);  // every label carries the three, detector_agreement too
  // The job for new recordings: the adapted network, the chosen thresholds, tracking;
  // it runs as written (on the same capture here).
  const JobConfig next = LoadJobConfig(out + "/new_recordings.yaml");
  EXPECT_EQ(next.network_weights, out + "/network.pt");
  EXPECT_EQ(next.quality.max_reprojection_px,
            chosen["max_reprojection_px"].get<double>());
  EXPECT_EQ(next.quality.max_view_disagreement_mm,
            chosen["max_view_disagreement_mm"].get<double>());
  EXPECT_EQ(next.quality.max_detector_rms_px,
            chosen["max_detector_rms_px"].get<double>());
  EXPECT_TRUE(next.keypoints_from_detector);
  EXPECT_GT(next.detector_every, 1);
  EXPECT_EQ(next.network_precision, "auto");
  const auto new_job =
      RunHandlabelCommand({"label", "--job", out + "/new_recordings.yaml"});
  ASSERT_EQ(new_job.status, 0) << new_job.err;
  // Frames where the detector finds the hand in no view fail by name (issue 46: they
  // were labelled from no 2D at all, about 20 cm off); every other frame is labelled.
  std::istringstream lines(new_job.err);
  int new_labelled = -1, failed = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("6 frames: ", 0) == 0) new_labelled = std::stoi(line.substr(10));
    if (line.rfind("  failed ", 0) != 0) continue;
    ++failed;
    EXPECT_THAT(line, HasSubstr("depth is not determined")) << line;
  }
  EXPECT_GE(new_labelled, 4) << new_job.err;
  EXPECT_EQ(new_labelled + failed, 6) << new_job.err;
  const std::string network = FileBytes(out + "/network.pt");

  // Run again: every stage was done, nothing is redone.
  const auto again = RunHandlabelCommand(command);
  ASSERT_EQ(again.status, 0) << again.err;
  for (const char* stage : kStages) {
    EXPECT_THAT(again.err, HasSubstr(std::string(stage) + ": done in an earlier run"));
  }
  // The export made again from the same checkpoints is the same file: averaging and
  // the batch-norm statistics measured on the capture are deterministic. The label
  // job then continues its folder (the weights' hash is the same).
  for (const char* stage : {"export", "heldout", "label"}) {
    fs::remove(out + "/stages/" + std::string(stage) + ".done");
  }
  fs::remove(out + "/network.pt");
  const auto exported = RunHandlabelCommand(command);
  ASSERT_EQ(exported.status, 0) << exported.err;
  EXPECT_EQ(FileBytes(out + "/network.pt"), network);

  // Another held-out block into the same folder: refused, naming the record.
  std::vector<std::string> other = command;
  other[std::find(other.begin(), other.end(), "4:6") - other.begin()] = "0:2";
  const auto refused = RunHandlabelCommand(other);
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("adapt.json"));
  EXPECT_THAT(refused.err, HasSubstr("heldout"));
}

// Two runs in one folder would train, export and label over each other: a second one
// is refused, naming the first, while the first runs.
TEST(AdaptCommand, ASecondRunIntoTheFolderIsRefusedWhileTheFirstRuns) {
  const std::string dir = testing::ScratchDir();
  const std::string weights = TinyWeights(dir), capture = SmallCapture(dir);
  const std::string out = dir + "/adapted";
  const std::vector<std::string> command = {
      "adapt", "--capture", capture, "--out",     out, "--weights",
      weights, "--budget",  "0.01",  "--threads", "1", "--no-overlays"};
  const pid_t first = testing::SpawnHandlabel(command, dir + "/first.log");
  ASSERT_TRUE(testing::WaitUntilHolding(first, out + "/adapt.lock"))
      << testing::ReadFileBytes(dir + "/first.log");
  kill(first, SIGSTOP);  // keeps the lock while the second tries
  const auto second = RunHandlabelCommand(command);
  EXPECT_EQ(second.status, 1);
  EXPECT_THAT(second.err, HasSubstr("--out"));
  EXPECT_THAT(second.err, HasSubstr("adapt, pid " + std::to_string(first)));
  kill(first, SIGKILL);
  EXPECT_EQ(testing::WaitForExit(first), -SIGKILL);
}

TEST(AdaptCommand, MissingWeightsAndBadBudgetNameTheFlag) {
  const std::string dir = testing::ScratchDir();
  const auto missing = RunHandlabelCommand(
      {"adapt", "--capture", dir, "--out", dir + "/a", "--weights", dir + "/none.pt"});
  EXPECT_EQ(missing.status, 1);
  EXPECT_THAT(missing.err, HasSubstr("--weights"));
  EXPECT_THAT(missing.err, HasSubstr("none.pt"));
  const auto budget = RunHandlabelCommand(
      {"adapt", "--capture", dir, "--out", dir + "/a", "--budget", "0"});
  EXPECT_EQ(budget.status, 1);
  EXPECT_THAT(budget.err, HasSubstr("--budget"));
  const auto share = RunHandlabelCommand(
      {"adapt", "--capture", dir, "--out", dir + "/a", "--synth-share", "1.5"});
  EXPECT_EQ(share.status, 1);
  EXPECT_THAT(share.err, HasSubstr("--synth-share"));
}

}  // namespace
}  // namespace handlabel
