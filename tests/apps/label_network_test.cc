// End-to-end tests of every refine mode with the real stages: the POEM network (a tiny
// configuration with random weights: the plumbing, not the accuracy, is under test),
// the quality checks and the Ceres fitter, on a synthetic capture.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "formats/sha256.h"
#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/poem_config.h"
#include "pipeline/label_record.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

std::string NetworkJob(const std::string& dir, const std::string& mode,
                       const std::string& weights = "tiny.pt",
                       const std::string& masks = "none") {
  const std::string path = dir + "/" + mode + "-" + masks + ".yaml";
  std::ofstream(path) << "name: net\nseed: 3\nhand_model: capsule\n"
                      << "input: {format: native, path: capture}\n"
                      << "network: {weights: " << weights
                      << ", threads: 2, batch_size: 2}\n"
                      << "refine: {mode: " << mode << "}\n"
                      << "evidence: {keypoints_2d: both, masks: " << masks << "}\n"
                      << "output: {dir: " << mode << "-" << masks
                      << ", overlays: false}\n";
  return path;
}

class LabelNetwork : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::ScratchDir();
    testing::WriteTestCapture(dir_ + "/capture", 2, 9);
    WriteRandomPoemCheckpoint(PoemConfigByName("tiny", 8), 4, dir_ + "/tiny.pt");
  }
  std::string dir_;
};

TEST_F(LabelNetwork, RefineOffLabelsEveryFrameWithTheNetworkAndItsQualityFlags) {
  const auto r = RunHandlabelCommand({"label", "--job", NetworkJob(dir_, "off")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("2 labelled (network 2)"));
  const LabelRecord label = ReadLabelFile(LabelFilePath(dir_ + "/off-none", "000000"));
  EXPECT_EQ(label.path, LabelPath::kNetwork);
  // The five checks against the network's own 2D, and detector_agreement: the job's
  // evidence (keypoints_2d: both) includes the capture's file 2D.
  ASSERT_EQ(label.quality.flags.size(), 6u);
  EXPECT_EQ(label.quality.flags.back().name, "detector_agreement");
  EXPECT_EQ(label.mesh.vertices.rows(), 778);
  EXPECT_EQ(label.provenance.weights_sha256, Sha256OfFile(dir_ + "/tiny.pt"));
  EXPECT_THAT(label.provenance.network_model, HasSubstr("poem"));
  EXPECT_FALSE(label.params.has_value());
}

TEST_F(LabelNetwork, FallbackFitsWhereTheRandomNetworkFailsItsChecks) {
  const auto r = RunHandlabelCommand({"label", "--job", NetworkJob(dir_, "fallback")});
  ASSERT_EQ(r.status, 0) << r.err;
  // Random weights never pass the checks: every frame falls back to the fit.
  EXPECT_THAT(r.err, HasSubstr("2 labelled (fallback_fit 2)"));
  const LabelRecord label =
      ReadLabelFile(LabelFilePath(dir_ + "/fallback-none", "000001"));
  EXPECT_FALSE(label.quality.Passed());
  EXPECT_THAT(label.fit.at("why").get<std::string>(), HasSubstr("quality checks failed"));
  EXPECT_THAT(r.err, HasSubstr("network_raw (2 frames)"));
}

TEST_F(LabelNetwork, AlwaysRefinesTheNetworkAnswer) {
  const auto r = RunHandlabelCommand({"label", "--job", NetworkJob(dir_, "always")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("2 labelled (refined 2)"));
  const LabelRecord label = ReadLabelFile(LabelFilePath(dir_ + "/always-none", "000000"));
  EXPECT_EQ(label.fit.at("init"), "network");
  ASSERT_TRUE(label.params.has_value());
}

TEST_F(LabelNetwork, NetworkSilhouettesNeedAMaskHead) {
  const auto r = RunHandlabelCommand(
      {"label", "--job", NetworkJob(dir_, "always", "tiny.pt", "network")});
  EXPECT_NE(r.status, 0);
  EXPECT_THAT(r.err, HasSubstr("evidence.masks"));
  EXPECT_THAT(r.err, HasSubstr("has no mask head"));
}

TEST_F(LabelNetwork, RefinementFitsTheMaskHeadsSilhouettes) {
  PoemConfig c = PoemConfigByName("tiny", 8);
  c.mask_head = true;
  WriteRandomPoemCheckpoint(c, 5, dir_ + "/tiny_masks.pt");
  const auto r = RunHandlabelCommand(
      {"label", "--job", NetworkJob(dir_, "always", "tiny_masks.pt", "network")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("2 labelled (refined 2)"));
  const LabelRecord label =
      ReadLabelFile(LabelFilePath(dir_ + "/always-network", "000000"));
  EXPECT_EQ(label.fit.at("silhouettes"), "network");
  // The default with the capture's detections among the evidence.
  EXPECT_EQ(label.fit.at("silhouette_sigma_px"), 16.0);
  // Silhouette agreement is measured in the views that got a predicted mask.
  int measured = 0;
  for (const auto& iou : label.fit.at("view_iou")) measured += iou.is_number();
  EXPECT_GT(measured, 0);
  // view_iou is measured after any solve; the silhouette term itself must have run.
  EXPECT_TRUE(label.fit.at("term_costs").contains("silhouette"));
  // Without `network` the same weights fit keypoints only, to a different answer.
  const auto plain = RunHandlabelCommand(
      {"label", "--job", NetworkJob(dir_, "always", "tiny_masks.pt", "none")});
  ASSERT_EQ(plain.status, 0) << plain.err;
  const LabelRecord plain_label =
      ReadLabelFile(LabelFilePath(dir_ + "/always-none", "000000"));
  EXPECT_EQ(plain_label.fit.at("silhouettes"), "none");
  EXPECT_FALSE(plain_label.fit.at("term_costs").contains("silhouette"));
  ASSERT_TRUE(label.params.has_value() && plain_label.params.has_value());
  // The silhouette check (docs/labeling-jobs.md "Silhouette conflict") keeps the
  // silhouette fit, a different answer, or falls back to the keypoints-only fit, the
  // plain label's answer; the random mask head usually disagrees with the keypoints.
  const double moved = (label.mesh.vertices - plain_label.mesh.vertices).norm();
  if (label.fit.at("used") == "silhouettes") {
    EXPECT_GT(moved, 1e-6);
  } else {
    EXPECT_EQ(label.fit.at("used"), "keypoints_only");
    EXPECT_THAT(label.fit.at("used_why").get<std::string>(),
                HasSubstr("silhouette check failed"));
    EXPECT_LT(moved, 1e-9);
  }
}

}  // namespace
}  // namespace handlabel
