#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "pipeline/label_outputs.h"
#include "pipeline/label_record.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::CommandResult;
using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

TEST(FitCommand, HelpDescribesTheOptions) {
  const CommandResult r = RunHandlabelCommand({"fit", "--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* option : {"--capture", "--init", "--evidence", "--masks", "--loss",
                             "--ignore-views", "--overlay", "--threads"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
}

TEST(FitCommand, MissingCaptureIsAnErrorNamingIt) {
  const std::string dir = testing::ScratchDir();
  const CommandResult r =
      RunHandlabelCommand({"fit", "--capture", dir + "/none", "--out", dir + "/out"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("none"), std::string::npos) << r.err;
}

TEST(FitCommand, BadLossIsAnError) {
  const std::string dir = testing::ScratchDir();
  const CommandResult r = RunHandlabelCommand(
      {"fit", "--capture", dir, "--out", dir + "/out", "--loss", "magic"});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--loss"), std::string::npos) << r.err;
}

TEST(FitCommand, BadUnknownOccludersIsAnErrorNamingTheFlag) {
  const std::string dir = testing::ScratchDir();
  const CommandResult r = RunHandlabelCommand(
      {"fit", "--capture", dir, "--out", dir + "/out", "--unknown-occluders", "x"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--unknown-occluders"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("one_sided | two_sided"), std::string::npos) << r.err;
}

// Runs `fit` with `flags` on a one-frame test capture in `dir`, then `label` with a job
// of the same `evidence` and `fit` sections (YAML flow mappings); both must write the
// same label files. Returns the fit's label of frame 000000.
LabelRecord FitEqualsLabelJob(const std::string& dir,
                              const std::vector<std::string>& flags,
                              const std::string& evidence, const std::string& fit) {
  testing::WriteTestCapture(dir + "/capture", 1, 6);
  std::vector<std::string> args = {"fit",    "--capture",  dir + "/capture",
                                   "--out",  dir + "/fit", "--hand-model",
                                   "capsule"};
  args.insert(args.end(), flags.begin(), flags.end());
  const CommandResult fit_run = RunHandlabelCommand(args);
  EXPECT_EQ(fit_run.status, 0) << fit_run.err;
  const std::string job = dir + "/job.yaml";
  std::ofstream(job) << "hand_model: capsule\n"
                     << "input: {format: native, path: capture}\n"
                     << "refine: {mode: always}\n"
                     << "evidence: " << evidence << "\n"
                     << "fit: " << fit << "\n"
                     << "output: {dir: label, overlays: false}\n";
  const CommandResult label = RunHandlabelCommand({"label", "--job", job});
  EXPECT_EQ(label.status, 0) << label.err;
  EXPECT_EQ(testing::FilesUnder(dir + "/fit/labels"),
            testing::FilesUnder(dir + "/label/labels"));
  return ReadLabelFile(LabelFilePath(dir + "/fit", "000000"));
}

// The silhouette flags are job fields too: --no-silhouette-check is
// fit.silhouette_check: false, --unknown-occluders is fit.unknown_occluders.
TEST(FitCommand, SilhouetteCheckFlagsMapToJobFields) {
  const LabelRecord record = FitEqualsLabelJob(
      testing::ScratchDir(),
      {"--evidence", "keypoints", "--masks", "truth", "--silhouette-rounds", "1",
       "--object-masks", "none", "--unknown-occluders", "one_sided",
       "--no-silhouette-check"},
      "{keypoints_2d: files, masks: files, keypoint_files: keypoints, mask_files: "
      "truth, object_masks: none}",
      "{silhouette_rounds: 1, silhouette_check: false, unknown_occluders: one_sided}");
  EXPECT_EQ(record.fit.at("silhouettes"), "files+one_sided");
  EXPECT_EQ(record.fit.at("used"), "silhouettes");
  EXPECT_EQ(record.fit.at("silhouette_check").size(), 2u);
}

// --mask-margin is fit.mask_margin_px; the label records the margin taken out per view,
// within the limit; bad values are reported against the flag.
TEST(FitCommand, MaskMarginFlagMapsToTheJobFieldAndIsRecorded) {
  const std::string dir = testing::ScratchDir();
  const LabelRecord record =
      FitEqualsLabelJob(dir, {"--silhouette-rounds", "1", "--mask-margin", "1.5"},
                        "{keypoints_2d: files, masks: files}",
                        "{silhouette_rounds: 1, mask_margin_px: 1.5}");
  const nlohmann::json& margins = record.fit.at("view_mask_margin_px");
  ASSERT_EQ(margins.size(), 8u);  // the test capture's cameras
  int estimated = 0;
  for (const nlohmann::json& m : margins) {
    if (m.is_null()) continue;
    EXPECT_LE(std::abs(m.get<double>()), 1.5);
    ++estimated;
  }
  EXPECT_GT(estimated, 0);
  const CommandResult bad =
      RunHandlabelCommand({"fit", "--capture", dir + "/capture", "--out", dir + "/bad",
                           "--mask-margin", "-2"});
  EXPECT_EQ(bad.status, 1);
  // The error names the flag the user typed, not the job field behind it.
  EXPECT_NE(bad.err.find("'--mask-margin': expected 0..50 (pixels), got -2"),
            std::string::npos)
      << bad.err;
  EXPECT_EQ(bad.err.find("mask_margin_px"), std::string::npos) << bad.err;
  const CommandResult bad_pca = RunHandlabelCommand(
      {"fit", "--capture", dir + "/capture", "--out", dir + "/bad", "--pca", "7"});
  EXPECT_NE(bad_pca.err.find("'--pca': expected 0, 12 or 45, got 7"), std::string::npos)
      << bad_pca.err;
}

// `fit` is a label job without a network: on the same capture it writes the same label
// files, byte for byte, as `label` with the matching job (default rules: detections
// and detection masks, triangulated start), and reports the errors against the truth.
TEST(FitCommand, WritesTheSameLabelsAsANetworkFreeLabelJob) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 3, 5);
  const CommandResult fit =
      RunHandlabelCommand({"fit", "--capture", dir + "/capture", "--out", dir + "/fit",
                           "--hand-model", "capsule", "--threads", "2"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_THAT(fit.out, HasSubstr("fitted 3 frames"));
  EXPECT_THAT(fit.out, HasSubstr("MPJPE"));
  const std::string job = dir + "/job.yaml";
  std::ofstream(job) << "name: same\nhand_model: capsule\n"
                     << "input: {format: native, path: capture}\n"
                     << "network: {threads: 1}\nrefine: {mode: always}\n"
                     << "evidence: {keypoints_2d: files, masks: files}\n"
                     << "output: {dir: label, overlays: false}\n";
  const CommandResult label = RunHandlabelCommand({"label", "--job", job});
  ASSERT_EQ(label.status, 0) << label.err;
  const auto fit_labels = testing::FilesUnder(dir + "/fit/labels");
  const auto job_labels = testing::FilesUnder(dir + "/label/labels");
  ASSERT_EQ(fit_labels.size(), 3u);
  EXPECT_EQ(fit_labels, job_labels);  // names and bytes
  const LabelRecord record = ReadLabelFile(LabelFilePath(dir + "/fit", "000002"));
  EXPECT_EQ(record.path, LabelPath::kFallbackFit);
  EXPECT_EQ(record.fit.at("silhouettes"), "files");
  const nlohmann::json summary =
      nlohmann::json::parse(testing::ReadFileBytes(SummaryJsonPath(dir + "/fit")));
  // Simulated detections and noisy masks at 160x120: within ~2 cm (15 mm measured).
  EXPECT_LT(summary.at("metrics").at("labels").at("mpjpe_mm").get<double>(), 20.0);
}

// Flags the job format had no field for are job fields now: a YAML job can ask for
// the same fit (here: exact keypoints, true masks, Huber loss, a camera left out).
TEST(FitCommand, FlagsMapToJobFields) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 2, 6);
  const CommandResult fit = RunHandlabelCommand(
      {"fit", "--capture", dir + "/capture", "--out", dir + "/fit", "--hand-model",
       "capsule", "--evidence", "keypoints", "--masks", "truth", "--loss", "huber",
       "--silhouette-rounds", "1", "--ignore-views", "cam00", "--max-frames", "1"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  const std::string job = dir + "/job.yaml";
  std::ofstream(job) << "hand_model: capsule\n"
                     << "input: {format: native, path: capture, max_frames: 1}\n"
                     << "refine: {mode: always}\n"
                     << "evidence: {keypoints_2d: files, masks: files, keypoint_files: "
                        "keypoints, mask_files: truth, ignore_views: [cam00]}\n"
                     << "fit: {keypoint_loss: huber, silhouette_rounds: 1}\n"
                     << "output: {dir: label, overlays: false}\n";
  const CommandResult label = RunHandlabelCommand({"label", "--job", job});
  ASSERT_EQ(label.status, 0) << label.err;
  const auto fit_labels = testing::FilesUnder(dir + "/fit/labels");
  ASSERT_EQ(fit_labels.size(), 1u);
  EXPECT_EQ(fit_labels, testing::FilesUnder(dir + "/label/labels"));
  // cam00 has neither keypoints nor a mask in the fit.
  const LabelRecord record = ReadLabelFile(LabelFilePath(dir + "/fit", "000000"));
  EXPECT_EQ(record.fit.at("view_rms_px").size(), 7u);
}

}  // namespace
}  // namespace handlabel
