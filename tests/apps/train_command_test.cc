// `handlabel train` and `handlabel eval-network` end to end on a tiny network: a short
// run, its export, then the mask head trained alone onto the exported weights, and the
// evaluation of the result (the plumbing, not the accuracy, is under test).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "capture/native_frame_source.h"
#include "core/json_util.h"
#include "image/image.h"
#include "pipeline/label_record.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

std::string TrainConfigFile(const std::string& dir, const std::string& name,
                            const std::string& extra_train, bool mask_head) {
  const std::string path = dir + "/" + name + ".yaml";
  std::ofstream(path) << "network: tiny\n"
                      << (mask_head ? "network_overrides: {mask_head: true}\n" : "")
                      << "hand_model: \"\"\n"
                      << "data: {preset: dexycb, width: 320, height: 240, seed: 4}\n"
                      << "train:\n  steps: 2\n  batch_size: 1\n  warmup_steps: 1\n"
                      << "  checkpoint_every: 1\n  log_every: 1\n  validate_every: 2\n"
                      << "  validation_samples: 2\n  prefetch_batches: 0\n"
                      << extra_train << "  out_dir: " << dir << "/" << name << "\n";
  return path;
}

// The error lines of an eval-network report (MPJPE, MPVPE, PA-..., AUC).
std::string MetricLines(const std::string& report) {
  std::istringstream in(report);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.rfind("MPJPE", 0) == 0 || line.rfind("MPVPE", 0) == 0 ||
        line.rfind("PA-", 0) == 0 || line.rfind("AUC", 0) == 0)
      out += line + "\n";
  }
  return out;
}

// eval-network's "(true mesh: X mm)": keypoints read off the true mesh vs the true ones.
double TrueMeshReadingMm(const std::string& report) {
  const std::string key = "(true mesh: ";
  const size_t at = report.find(key);
  return at == std::string::npos ? -1 : std::stod(report.substr(at + key.size()));
}

TEST(TrainCommand, TrainsExportsAndTrainsAMaskHeadOntoTheExport) {
  const std::string dir = testing::ScratchDir();
  const auto base =
      RunHandlabelCommand({"train", "--config", TrainConfigFile(dir, "base", "", false)});
  ASSERT_EQ(base.status, 0) << base.err;
  EXPECT_THAT(base.out, HasSubstr("validation at step 2: MPJPE"));
  const auto exported =
      RunHandlabelCommand({"train", "--config", TrainConfigFile(dir, "base", "", false),
                           "--export", dir + "/base.pt"});
  ASSERT_EQ(exported.status, 0) << exported.err;
  ASSERT_TRUE(std::filesystem::exists(dir + "/base.pt"));

  const std::string masks_config = TrainConfigFile(
      dir, "masks", "  trainable: mask_head\n  learning_rate: 0.01\n", true);
  const auto masks = RunHandlabelCommand(
      {"train", "--config", masks_config, "--init-weights", dir + "/base.pt"});
  ASSERT_EQ(masks.status, 0) << masks.err;
  EXPECT_THAT(masks.out, HasSubstr(" masks "));
  EXPECT_THAT(masks.out, HasSubstr("mask IoU"));
  std::ifstream csv(dir + "/masks/validation.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "step,mpjpe_mm,mpvpe_mm,samples,mask_iou");
  ASSERT_EQ(RunHandlabelCommand(
                {"train", "--config", masks_config, "--export", dir + "/masks.pt"})
                .status,
            0);
  const auto eval =
      RunHandlabelCommand({"eval-network", "--weights", dir + "/masks.pt", "--preset",
                           "dexycb", "--frames", "2", "--seed", "9"});
  ASSERT_EQ(eval.status, 0) << eval.err;
  EXPECT_THAT(eval.out, HasSubstr("mask IoU (crop grid)"));
  // The head was trained onto the exported weights and nothing else moved: the mesh
  // answers, hence every error, are the base network's to the last digit.
  const auto eval_base =
      RunHandlabelCommand({"eval-network", "--weights", dir + "/base.pt", "--preset",
                           "dexycb", "--frames", "2", "--seed", "9"});
  ASSERT_EQ(eval_base.status, 0) << eval_base.err;
  EXPECT_EQ(MetricLines(eval.out), MetricLines(eval_base.out));
  ASSERT_FALSE(MetricLines(eval.out).empty());
  // Keypoints read off the true mesh sit within the joint regressor's small error of the
  // true keypoints (the open hand: about 0.5 mm; a wrong joint order or tip vertex would
  // be tens of mm), and that reading does not depend on the weights.
  const double true_mesh = TrueMeshReadingMm(eval.out);
  EXPECT_GT(true_mesh, 0);
  EXPECT_LT(true_mesh, 2.0);
  EXPECT_EQ(true_mesh, TrueMeshReadingMm(eval_base.out));
}

// Rows of loss.csv as step -> lr.
std::map<int, double> LearningRates(const std::string& csv_path) {
  std::ifstream csv(csv_path);
  std::string line;
  std::getline(csv, line);  // header: step,lr,...
  std::map<int, double> lr;
  while (std::getline(csv, line)) {
    const size_t comma = line.find(',');
    lr[std::stoi(line.substr(0, comma))] = std::stod(line.substr(comma + 1));
  }
  return lr;
}

TEST(TrainCommand, ResumesWithLongerScheduleAndNewLearningRate) {
  const std::string dir = testing::ScratchDir();
  const std::string config =
      TrainConfigFile(dir, "run", "  learning_rate: 0.001\n  decay_at: 1.0\n", false);
  ASSERT_EQ(RunHandlabelCommand({"train", "--config", config}).status, 0);
  const auto resumed =
      RunHandlabelCommand({"train", "--config", config, "--resume", "--steps", "4",
                           "--learning-rate", "0.0002", "--stop-at", "3"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_THAT(resumed.out, HasSubstr("step 3/4 (stop at 3) loss "));
  const std::map<int, double> lr = LearningRates(dir + "/run/loss.csv");
  ASSERT_EQ(lr.size(), 3u);
  EXPECT_DOUBLE_EQ(lr.at(2), 0.001);   // the first run's schedule, after warm-up
  EXPECT_DOUBLE_EQ(lr.at(3), 0.0002);  // the resumed run's
  // A learning rate that is not positive is bad usage, not silently ignored.
  const auto bad = RunHandlabelCommand(
      {"train", "--config", config, "--resume", "--learning-rate", "0"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.err, HasSubstr("--learning-rate"));
}

// A disk that fills up while a checkpoint is written (here: a file size limit below the
// checkpoint's size; the write fails like on a full disk) ended the process with an
// uncaught LibTorch error (exit 134). Now: exit 1 naming the file, no partial
// checkpoint or temporary left; a resume with room finishes. A resume with another
// data seed or batch size is refused naming the setting.
TEST(TrainCommand, AFullDiskNamesTheCheckpointAndOtherDataRefusesTheResume) {
  const std::string dir = testing::ScratchDir();
  const std::string config = TrainConfigFile(dir, "run", "", false);
  ASSERT_EQ(testing::WaitForExit(testing::SpawnHandlabel({"train", "--config", config},
                                                          dir + "/full.log", 16384)),
            1);
  const std::string log = testing::ReadFileBytes(dir + "/full.log");
  EXPECT_THAT(log, HasSubstr("cannot write '" + dir + "/run/checkpoints/step_00000001.pt'"));
  EXPECT_THAT(log, HasSubstr("File too large"));  // EFBIG; a full disk says ENOSPC
  EXPECT_THAT(log, ::testing::Not(HasSubstr("Exception raised from")));
  for (const auto& [name, bytes] : testing::FilesUnder(dir + "/run")) {
    EXPECT_THAT(name, ::testing::Not(HasSubstr(".tmp"))) << name;
    EXPECT_THAT(name, ::testing::Not(HasSubstr("checkpoints/"))) << name;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/run/latest.json"));
  const auto resumed = RunHandlabelCommand({"train", "--config", config, "--resume"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;

  std::string other = testing::ReadFileBytes(config);
  other.replace(other.find("seed: 4"), 7, "seed: 5");
  std::ofstream(dir + "/other.yaml") << other;
  const auto refused = RunHandlabelCommand(
      {"train", "--config", dir + "/other.yaml", "--resume", "--steps", "3"});
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("latest.json: field 'data.synth.seed'"));
  EXPECT_THAT(refused.err, HasSubstr("got 5"));
}

TEST(TrainCommand, KeepEveryAndExportTheAverageOfCheckpoints) {
  const std::string dir = testing::ScratchDir();
  const std::string config =
      TrainConfigFile(dir, "run", "  keep_checkpoints: 1\n  keep_every: 1\n", false);
  ASSERT_EQ(RunHandlabelCommand({"train", "--config", config}).status, 0);
  const std::string one = dir + "/run/checkpoints/step_00000001.pt",
                    two = dir + "/run/checkpoints/step_00000002.pt";
  ASSERT_TRUE(std::filesystem::exists(one));  // kept by keep_every despite keep 1
  EXPECT_FALSE(std::filesystem::exists(dir + "/run/checkpoints/step_00000001.optim"));
  const auto averaged = RunHandlabelCommand(
      {"train", "--config", config, "--export", dir + "/mean.pt", "--average", one, two});
  ASSERT_EQ(averaged.status, 0) << averaged.err;
  EXPECT_THAT(averaged.out, HasSubstr("mean of 2 checkpoints"));
  const auto eval = RunHandlabelCommand({"eval-network", "--weights", dir + "/mean.pt",
                                         "--preset", "dexycb", "--frames", "1"});
  EXPECT_EQ(eval.status, 0) << eval.err;
  const auto updated =
      RunHandlabelCommand({"train", "--config", config, "--export", dir + "/mean_bn.pt",
                           "--average", one, two, "--bn-samples", "2"});
  ASSERT_EQ(updated.status, 0) << updated.err;
  EXPECT_THAT(updated.out, HasSubstr("batch-norm statistics from 2 samples"));
  EXPECT_NE(testing::ReadFileBytes(dir + "/mean.pt"),
            testing::ReadFileBytes(dir + "/mean_bn.pt"));
  EXPECT_EQ(RunHandlabelCommand({"train", "--config", config, "--export", dir + "/x.pt",
                                 "--bn-samples", "2"})
                .status,
            2);  // --bn-samples needs --average
  // --average names checkpoints to export; alone it is bad usage.
  const auto alone = RunHandlabelCommand({"train", "--config", config, "--average", one});
  EXPECT_EQ(alone.status, 2);
  EXPECT_THAT(alone.err, HasSubstr("--export"));
}

TEST(TrainCommand, MaskPictureNeedsAMaskHead) {
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(
      RunHandlabelCommand({"train", "--config", TrainConfigFile(dir, "plain", "", false)})
          .status,
      0);
  ASSERT_EQ(
      RunHandlabelCommand({"train", "--config", TrainConfigFile(dir, "plain", "", false),
                           "--export", dir + "/plain.pt"})
          .status,
      0);
  const auto r = RunHandlabelCommand({"eval-network", "--weights", dir + "/plain.pt",
                                      "--frames", "1", "--mask-png", dir + "/m.png"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("--mask-png"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/m.png"));
}

// A 4-frame synthetic capture made by `handlabel synth` (the open hand, so the labels
// have the network's 778 vertices) and a labels/ folder of its ground truth.
std::string CaptureWithTruthLabels(const std::string& dir) {
  const std::string capture = dir + "/capture";
  const auto synth =
      RunHandlabelCommand({"synth", "--preset", "dexycb", "--frames", "4", "--seed", "2",
                           "--size", "160x120", "--threads", "1", "--out", capture});
  EXPECT_EQ(synth.status, 0) << synth.err;
  const NativeFrameSource source(capture);
  for (const std::string& id : source.FrameIds()) {
    const FrameGroundTruth truth = *source.Load(id).ground_truth;
    LabelRecord label;
    label.frame = id;
    label.path = LabelPath::kFallbackFit;
    label.mesh.keypoints = truth.keypoints;
    label.mesh.vertices = truth.vertices;
    label.mesh.joints = Points3d::Zero(kNumHandJoints, 3);
    // A fit agreeing with its 2D in every view: the label selection keeps it.
    label.fit = {{"view_rms_px", std::vector<double>(source.Load(id).rig.size(), 1.0)}};
    WriteLabelFiles(dir + "/fit", label, Faces(), {});
  }
  return capture;
}

// Training on a capture's labels, mixed half and half with synthetic samples, validated
// on a held-out frame of the capture before the first step and at the end.
TEST(TrainCommand, TrainsOnACapturesLabelsAndValidatesBeforeTheFirstStep) {
  const std::string dir = testing::ScratchDir();
  const std::string capture = CaptureWithTruthLabels(dir);
  const std::string config = TrainConfigFile(dir, "real", "", false);
  const auto run = RunHandlabelCommand(
      {"train", "--config", config, "--capture", capture, "--labels", dir + "/fit/labels",
       "--train-frames", "0:3", "--val-frames", "3:4", "--real-share", "0.5"});
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_THAT(run.err, HasSubstr("3 training (0 labels left out, capture_labels.json) "
                                 "and 1 validation frames"));
  const nlohmann::json selection = ReadJsonFileStrict(dir + "/real/capture_labels.json");
  EXPECT_EQ(selection["kept"], 3);
  EXPECT_EQ(selection["min_views"], 3);
  EXPECT_THAT(run.out, HasSubstr("validation at step 0: MPJPE"));
  EXPECT_THAT(run.out, HasSubstr("validation at step 2: MPJPE"));
  std::ifstream csv(dir + "/real/validation.csv");
  std::string header, first, last;
  std::getline(csv, header);
  std::getline(csv, first);
  std::getline(csv, last);
  EXPECT_EQ(first.substr(0, 2), "0,");
  EXPECT_EQ(last.substr(0, 2), "2,");
  EXPECT_EQ(last.substr(last.rfind(',') + 1), "1");  // one sample per held-out frame

  // Resumed: the start is not validated again.
  const auto resumed = RunHandlabelCommand(
      {"train", "--config", config, "--resume", "--steps", "3", "--capture", capture,
       "--labels", dir + "/fit/labels", "--val-frames", "3:4", "--real-share", "0.5"});
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_THAT(resumed.out, ::testing::Not(HasSubstr("validation at step 2")));

  const auto outside = RunHandlabelCommand(
      {"train", "--config", TrainConfigFile(dir, "bad", "", false), "--capture", capture,
       "--labels", dir + "/fit/labels", "--train-frames", "0:9"});
  EXPECT_EQ(outside.status, 1);
  EXPECT_THAT(outside.err, HasSubstr("--train-frames"));
  const auto no_labels =
      RunHandlabelCommand({"train", "--config", config, "--capture", capture});
  EXPECT_EQ(no_labels.status, 2);
  EXPECT_THAT(no_labels.err, HasSubstr("--labels"));
}

// The batch-norm update of an averaged export measures on the capture's training
// frames with --capture (the data the weights will label), not on synthetic ones:
// a different file from the synthetic update, and made again, the same bytes.
TEST(TrainCommand, BatchNormOfAnExportFromTheCapturesFrames) {
  const std::string dir = testing::ScratchDir();
  const std::string capture = CaptureWithTruthLabels(dir);
  const std::string config =
      TrainConfigFile(dir, "run", "  keep_checkpoints: 1\n  keep_every: 1\n", false);
  ASSERT_EQ(RunHandlabelCommand({"train", "--config", config}).status, 0);
  const std::string one = dir + "/run/checkpoints/step_00000001.pt",
                    two = dir + "/run/checkpoints/step_00000002.pt";
  const auto export_to = [&](const std::string& out, bool from_capture) {
    std::vector<std::string> args = {"train", "--config", config, "--export", out,
                                     "--average", one, two, "--bn-samples", "2"};
    if (from_capture) {
      for (const std::string& a : {std::string("--capture"), capture,
                                   std::string("--labels"), dir + "/fit/labels",
                                   std::string("--train-frames"), std::string("0:3")}) {
        args.push_back(a);
      }
    }
    return RunHandlabelCommand(args);
  };
  const auto synthetic = export_to(dir + "/synthetic_bn.pt", false);
  ASSERT_EQ(synthetic.status, 0) << synthetic.err;
  const auto real = export_to(dir + "/capture_bn.pt", true);
  ASSERT_EQ(real.status, 0) << real.err;
  EXPECT_THAT(real.out, HasSubstr("from 2 samples of the capture's frames"));
  // (Checkpoint archives name their file inside: compare files of one name.)
  std::filesystem::create_directories(dir + "/again");
  ASSERT_EQ(export_to(dir + "/again/synthetic_bn.pt", true).status, 0);
  EXPECT_TRUE(testing::ReadFileBytes(dir + "/synthetic_bn.pt") !=
              testing::ReadFileBytes(dir + "/again/synthetic_bn.pt"));
  ASSERT_EQ(export_to(dir + "/again/capture_bn.pt", true).status, 0);
  EXPECT_TRUE(testing::ReadFileBytes(dir + "/capture_bn.pt") ==
              testing::ReadFileBytes(dir + "/again/capture_bn.pt"));
}

TEST(TrainCommand, MaskHeadTrainingNeedsAHead) {
  const std::string dir = testing::ScratchDir();
  const auto r = RunHandlabelCommand(
      {"train", "--config",
       TrainConfigFile(dir, "bad", "  trainable: mask_head\n", /*mask_head=*/false)});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("train.trainable"));
  EXPECT_THAT(r.err, HasSubstr("network_overrides: {mask_head: true}"));
}

}  // namespace
}  // namespace handlabel
