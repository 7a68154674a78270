#include "pipeline/fit_capture.h"

#include <gtest/gtest.h>

#include <iostream>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/synth_capture.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "pipeline/label_record.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// A small synthetic capture (capsule hand, DexYCB-like rig at 160x120, objects when
// asked).
std::string SmallCapture(const std::string& scratch, int frames, bool objects = false) {
  const std::string dir = scratch + "/capture";
  SynthCaptureOptions o;
  o.scene.objects = objects;
  o.rig.preset = "dexycb";
  o.rig.width = 160;
  o.rig.height = 120;
  o.num_frames = frames;
  o.seed = 3;
  o.num_threads = 1;
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, dir, "builtin:capsule");
  return dir;
}

TEST(FitCaptureTest, ExactKeypointsRecoverGroundTruth) {
  const std::string scratch = testing::ScratchDir();  // one call: a second clears it
  FitCaptureOptions o;
  o.capture_dir = SmallCapture(scratch, 2);
  o.out_dir = scratch + "/fit";
  o.evidence = "keypoints";
  o.masks = "none";
  o.hand_model = "capsule";
  const FitCaptureSummary s = FitCapture(o);
  EXPECT_EQ(s.frames, 2);
  EXPECT_EQ(s.job.ok, 2);
  EXPECT_TRUE(s.has_ground_truth);
  EXPECT_LT(s.mpjpe, 0.001);
  EXPECT_GT(s.auc_joints, 0.9);
  std::ifstream in(s.summary_path);
  const nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["frames"], 2);
  EXPECT_LT(summary.at("metrics").at("labels").at("mpjpe_mm").get<double>(), 1.0);
  EXPECT_TRUE(std::filesystem::exists(LabelFilePath(o.out_dir, "000000")));
  // The fitted labels serve as an initialisation folder for a second run.
  FitCaptureOptions again = o;
  again.fit.init = o.out_dir;
  again.out_dir = scratch + "/fit2";
  const FitCaptureSummary from_labels = FitCapture(again);
  EXPECT_LT(from_labels.mpjpe, 0.001);
  EXPECT_EQ(ReadLabelFile(LabelFilePath(again.out_dir, "000001")).fit.at("init"), "file");
}

// --init previous: frames run in order, each fit starting from the previous label.
// Hands holding objects, exact keypoints and the true (visible) hand masks: with the
// capture's object masks as occluders the silhouettes agree with the keypoints; without
// them they pull the hand out of the object's pixels.
TEST(FitCaptureTest, ObjectMasksKeepTheSilhouettesFromPullingTheHandOut) {
  const std::string scratch = testing::ScratchDir();
  FitCaptureOptions o;
  o.capture_dir = SmallCapture(scratch, 4, /*objects=*/true);
  o.evidence = "keypoints";
  o.masks = "truth";
  o.hand_model = "capsule";
  o.num_threads = 2;
  o.out_dir = scratch + "/aware";
  const FitCaptureSummary aware = FitCapture(o);
  o.out_dir = scratch + "/unaware";
  o.object_masks = "none";
  o.fit.unknown_occluders = "two_sided";  // as if the frames were free of objects
  o.fit.silhouette_check = false;
  const FitCaptureSummary unaware = FitCapture(o);
  RecordProperty("aware_um", int(1e6 * aware.mpjpe));
  RecordProperty("unaware_um", int(1e6 * unaware.mpjpe));
  std::cout << "object masks: MPJPE " << 1e3 * aware.mpjpe << " mm, without "
            << 1e3 * unaware.mpjpe << " mm\n";
  EXPECT_EQ(aware.job.ok, 4);
  EXPECT_LT(aware.mpjpe, 0.002);
  EXPECT_GT(unaware.mpjpe, 1.5 * aware.mpjpe);
  const LabelRecord label = ReadLabelFile(LabelFilePath(scratch + "/aware", "000000"));
  EXPECT_EQ(label.fit.value("silhouettes", ""), "files+object_masks");
  EXPECT_EQ(label.fit.value("used", ""), "silhouettes");
}

// The same capture without object masks: the two-sided silhouettes pull the hand out of
// the objects' pixels, the silhouette check notices that the fit left the keypoints and
// the label is the keypoints-only fit (the default); unchecked, the labels are far off.
TEST(FitCaptureTest, WithoutObjectMasksTheSilhouetteCheckFallsBackToKeypoints) {
  const std::string scratch = testing::ScratchDir();
  FitCaptureOptions o;
  o.capture_dir = SmallCapture(scratch, 4, /*objects=*/true);
  o.evidence = "keypoints";
  o.hand_model = "capsule";
  o.num_threads = 2;
  o.masks = "none";
  o.out_dir = scratch + "/keypoints";
  const FitCaptureSummary keypoints = FitCapture(o);
  o.masks = "truth";
  o.object_masks = "none";
  o.out_dir = scratch + "/checked";
  const FitCaptureSummary checked = FitCapture(o);
  o.fit.silhouette_check = false;
  o.out_dir = scratch + "/unchecked";
  const FitCaptureSummary unchecked = FitCapture(o);
  o.fit.unknown_occluders = "one_sided";
  o.out_dir = scratch + "/one_sided";
  FitCapture(o);
  std::cout << "MPJPE mm: keypoints only " << 1e3 * keypoints.mpjpe
            << ", two-sided + check " << 1e3 * checked.mpjpe << ", unchecked "
            << 1e3 * unchecked.mpjpe << "\n";
  EXPECT_LT(checked.mpjpe, keypoints.mpjpe + 0.0005);
  EXPECT_GT(unchecked.mpjpe, checked.mpjpe + 0.002);
  int fell_back = 0;
  for (const char* frame : {"000000", "000001", "000002", "000003"}) {
    const LabelRecord label = ReadLabelFile(LabelFilePath(scratch + "/checked", frame));
    EXPECT_EQ(label.fit.value("silhouettes", ""), "files");
    ASSERT_EQ(label.fit.at("silhouette_check").size(), 2u);
    if (label.fit.value("used", "") != "keypoints_only") continue;
    ++fell_back;
    EXPECT_NE(label.fit.value("used_why", "").find("silhouette check failed"),
              std::string::npos);
  }
  EXPECT_GT(fell_back, 0);
  const LabelRecord unchecked_label =
      ReadLabelFile(LabelFilePath(scratch + "/unchecked", "000000"));
  EXPECT_EQ(unchecked_label.fit.value("used", ""), "silhouettes");
  const LabelRecord one_sided =
      ReadLabelFile(LabelFilePath(scratch + "/one_sided", "000000"));
  EXPECT_EQ(one_sided.fit.value("silhouettes", ""), "files+one_sided");
}

TEST(FitCaptureTest, PreviousStartsFromThePreviousLabel) {
  const std::string scratch = testing::ScratchDir();
  FitCaptureOptions o;
  o.capture_dir = SmallCapture(scratch, 3);
  o.out_dir = scratch + "/fit";
  o.evidence = "keypoints";
  o.masks = "none";
  o.hand_model = "capsule";
  o.fit.init = "previous";
  const FitCaptureSummary s = FitCapture(o);
  EXPECT_EQ(s.job.ok, 3);
  EXPECT_LT(s.mpjpe, 0.003);  // the temporal pull costs a little against exact keypoints
  EXPECT_EQ(ReadLabelFile(LabelFilePath(o.out_dir, "000000")).fit.at("init"),
            "triangulated_views");
  EXPECT_EQ(ReadLabelFile(LabelFilePath(o.out_dir, "000002")).fit.at("init"),
            "previous_label");
}

TEST(FitCaptureTest, BadOptionsNameTheFlag) {
  FitCaptureOptions o;
  o.capture_dir = "x";
  o.out_dir = "y";
  o.evidence = "magic";
  try {
    o.Check("test");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "--evidence");
  }
}

}  // namespace
}  // namespace handlabel
