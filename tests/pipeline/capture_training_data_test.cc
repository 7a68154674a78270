#include "pipeline/capture_training_data.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "capture/native_frame_source.h"
#include "capture/synth_capture.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "pipeline/label_record.h"
#include "pipeline/network_stage.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A 3-frame synthetic capture (DexYCB-like rig at 160 x 120, the simulated detector's
// keypoints in detections/) and a labels/ folder holding its ground truth as labels.
class CaptureTrainingDataTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string scratch = testing::ScratchDir();
    inputs_.capture_dir = scratch + "/capture";
    SynthCaptureOptions o;
    o.rig.preset = "dexycb";
    o.rig.width = 160;
    o.rig.height = 120;
    o.num_frames = 3;
    o.seed = 12;
    o.num_threads = 1;
    WriteSynthCapture(hand_, o, inputs_.capture_dir, "builtin:capsule");
    const NativeFrameSource source(inputs_.capture_dir);
    frames_ = source.FrameIds();
    for (const std::string& id : frames_) {
      const FrameGroundTruth truth = *source.Load(id).ground_truth;
      LabelRecord label;
      label.frame = id;
      label.path = LabelPath::kFallbackFit;
      label.mesh.keypoints = truth.keypoints;
      label.mesh.vertices = truth.vertices;
      label.mesh.joints = Points3d::Zero(kNumHandJoints, 3);
      // A fit that agrees with its 2D in every view (the label selection reads it).
      label.fit = {{"view_rms_px", std::vector<double>(8, 1.0)}};
      WriteLabelFiles(scratch + "/fit", label, hand_.faces, {});
    }
    inputs_.labels_dir = scratch + "/fit/labels";
  }

  std::string LabelPathOf(int position) const {
    return inputs_.labels_dir + "/" + FrameFileStem(frames_[position], "test") + ".json";
  }
  int num_vertices() const { return hand_.num_vertices(); }

  const HandModel hand_ = MakeCapsuleHand(HandSide::kRight);
  CaptureTrainingInputs inputs_;
  std::vector<std::string> frames_;
};

TEST_F(CaptureTrainingDataTest, SplitsFramesAndReadsTheLabelsAsTargets) {
  inputs_.val_frames = "2:3";
  const CaptureTrainingData data = LoadCaptureTrainingData(inputs_, num_vertices());
  ASSERT_EQ(data.train.size(), 2u);  // every frame that does not validate
  ASSERT_EQ(data.validation.size(), 1u);
  EXPECT_EQ(data.train[0].id, frames_[0]);
  EXPECT_EQ(data.train[1].id, frames_[1]);
  EXPECT_EQ(data.validation[0].id, frames_[2]);
  const FrameGroundTruth truth = *data.source->Load(frames_[2]).ground_truth;
  // Labels store coordinates rounded for the file; a micrometre is far below that.
  EXPECT_THAT(data.validation[0].keypoints_3d,
              testing::MatrixNear(truth.keypoints, 1e-6));
  EXPECT_THAT(data.validation[0].vertices, testing::MatrixNear(truth.vertices, 1e-6));
}

// The capture with the detector's keypoints of view 3 dropped (a view it missed).
class MissedView3 : public FrameSource {
 public:
  explicit MissedView3(const FrameSource& inner) : inner_(inner) {}
  std::vector<std::string> FrameIds() const override { return inner_.FrameIds(); }
  FrameInput Load(const std::string& id) const override {
    FrameInput frame = inner_.Load(id);
    if (frame.keypoints_2d[3]) frame.keypoints_2d[3]->confidence.setZero();
    return frame;
  }
  std::string Describe() const override { return "view 3 missed"; }

 private:
  const FrameSource& inner_;
};

// The validation samples are what the label job's network stage hands to the network:
// the same pixels, intrinsics, camera-to-master transforms and view weights, in views
// the detections locate (cropped around them) and views they miss (the whole image at
// weight 0) alike.
TEST_F(CaptureTrainingDataTest, ValidationSamplesAreTheNetworkStagesInput) {
  const CaptureTrainingData data = LoadCaptureTrainingData(inputs_, num_vertices());
  TrainConfig config;
  config.network = TinyPoemConfig(8);
  const CaptureSampleOptions options = CaptureSampleOptionsFor(config, true);
  EXPECT_EQ(options.crop_size, config.network.crop_size);
  const MissedView3 source(*data.source);
  for (const LabeledFrame& label : data.train) {
    const CaptureTrainingSamples samples(source, {label}, options);
    const TrainingSample sample = samples.Sample(0);
    const FrameInput frame = source.Load(label.id);
    HandCropOptions crop;
    crop.crop_size = config.network.crop_size;
    std::vector<ViewCrop> crops;
    const HandMeshInput input = CropFrameForNetwork(frame, 8, crop, &crops);
    int located = 0;
    for (size_t v = 0; v < crops.size(); ++v) {
      located += crops[v].source == "keypoints";
      EXPECT_EQ(sample.views[v].image, input.views[v].pixels) << "view " << v;
      EXPECT_EQ(sample.views[v].intrinsics, input.views[v].intrinsics) << "view " << v;
      EXPECT_EQ(sample.views[v].view_weight, input.views[v].weight) << "view " << v;
      Eigen::Matrix4d master_from_cam = Eigen::Matrix4d::Identity();
      master_from_cam.topRows<3>() = input.views[v].cam_from_master.Inverse().ToMatrix();
      EXPECT_EQ(sample.views[v].master_from_cam, master_from_cam) << "view " << v;
    }
    EXPECT_GE(located, 4) << label.id;
    EXPECT_EQ(crops[3].source, "whole image");
    EXPECT_EQ(sample.views[3].view_weight, 0.0f);
  }
}

TEST_F(CaptureTrainingDataTest, BadRangesNameTheFlag) {
  inputs_.train_frames = "0:9";
  std::string error =
      testing::InputErrorOf([&] { LoadCaptureTrainingData(inputs_, num_vertices()); });
  EXPECT_THAT(error, HasSubstr("--train-frames"));
  EXPECT_THAT(error, HasSubstr("3 frames"));
  inputs_.train_frames = "0:2";
  inputs_.val_frames = "1:3";
  error =
      testing::InputErrorOf([&] { LoadCaptureTrainingData(inputs_, num_vertices()); });
  EXPECT_THAT(error, HasSubstr("--val-frames"));
  EXPECT_THAT(error, HasSubstr(frames_[1]));
  inputs_.train_frames = "";
  inputs_.val_frames = "x:y";
  error =
      testing::InputErrorOf([&] { LoadCaptureTrainingData(inputs_, num_vertices()); });
  EXPECT_THAT(error, HasSubstr("--val-frames"));
}

TEST_F(CaptureTrainingDataTest, MissingOrIncompleteLabelsNameTheFileAndField) {
  fs::remove(LabelPathOf(1));
  std::string error =
      testing::InputErrorOf([&] { LoadCaptureTrainingData(inputs_, num_vertices()); });
  EXPECT_THAT(error, HasSubstr(LabelPathOf(1)));
  EXPECT_THAT(error, HasSubstr("label file"));

  inputs_.train_frames = "0:1";  // frame 1 no longer needed
  EXPECT_EQ(LoadCaptureTrainingData(inputs_, num_vertices()).train.size(), 1u);

  nlohmann::json label;
  std::ifstream(LabelPathOf(0)) >> label;
  label.erase("keypoints_3d");
  std::ofstream(LabelPathOf(0)) << label.dump();
  error =
      testing::InputErrorOf([&] { LoadCaptureTrainingData(inputs_, num_vertices()); });
  EXPECT_THAT(error, HasSubstr(LabelPathOf(0)));
  EXPECT_THAT(error, HasSubstr("keypoints_3d"));

  inputs_.train_frames = "2:3";
  error = testing::InputErrorOf(
      [&] { LoadCaptureTrainingData(inputs_, num_vertices() + 1); });
  EXPECT_THAT(error, HasSubstr("vertices"));
  EXPECT_THAT(error, HasSubstr(std::to_string(num_vertices() + 1)));
}

// A fit label whose report gives these per-view RMS values (null: no 2D in that view).
LabelRecord FitLabel(const nlohmann::json& view_rms_px) {
  LabelRecord label;
  label.frame = "f";
  label.path = LabelPath::kFallbackFit;
  label.fit = {{"view_rms_px", view_rms_px}};
  return label;
}

TEST(LabelSelection, AFitTrainsWhenEnoughViewsAgreeWithItsTwoD) {
  const LabelSelectionRule rule;  // 3 views within 10 px
  EXPECT_TRUE(SelectTrainingLabel(FitLabel({1, 10, 9.5, 40, nullptr}), rule).kept);
  const LabelSelection two = SelectTrainingLabel(FitLabel({1, 10.5, 9.5, 40}), rule);
  EXPECT_FALSE(two.kept);
  EXPECT_EQ(two.why, "2 of 4 views within 10 px");
  // No report (a label written without a fit): nothing shows it agrees with the 2D.
  LabelRecord bare = FitLabel(nullptr);
  bare.fit = nullptr;
  EXPECT_FALSE(SelectTrainingLabel(bare, rule).kept);
}

TEST(LabelSelection, ANetworkAnswerTrainsOnlyIfItPassedEveryCheck) {
  LabelRecord label;
  label.frame = "f";
  label.path = LabelPath::kNetwork;
  label.quality.flags = {{"reprojection", true, 3, 12, ""}};
  EXPECT_TRUE(SelectTrainingLabel(label, {}).kept);
  label.quality.flags.push_back({"view_agreement", false, 9, 6, ""});
  const LabelSelection s = SelectTrainingLabel(label, {});
  EXPECT_FALSE(s.kept);
  EXPECT_THAT(s.why, HasSubstr("view_agreement"));
}

TEST_F(CaptureTrainingDataTest, LabelsTheRuleLeavesOutDoNotTrainAndAreRecorded) {
  nlohmann::json label;
  std::ifstream(LabelPathOf(1)) >> label;
  label["fit"]["view_rms_px"] = {1, 1, 30, 30, 30, 30, 30, 30};
  std::ofstream(LabelPathOf(1)) << label.dump();
  inputs_.val_frames = "2:3";
  const CaptureTrainingData data = LoadCaptureTrainingData(inputs_, num_vertices());
  ASSERT_EQ(data.train.size(), 1u);
  EXPECT_EQ(data.train[0].id, frames_[0]);
  ASSERT_EQ(data.selection.size(), 2u);
  EXPECT_FALSE(data.selection[1].kept);
  const nlohmann::json record = LabelSelectionJson(inputs_.selection, data.selection);
  EXPECT_EQ(record["kept"], 1);
  EXPECT_EQ(record["training_frames"], 2);
  EXPECT_EQ(record["frames"][1]["frame"], frames_[1]);
  // Held-out frames are judged whatever their labels score.
  inputs_.train_frames = "0:1";
  inputs_.val_frames = "1:2";
  EXPECT_EQ(LoadCaptureTrainingData(inputs_, num_vertices()).validation.size(), 1u);
  // A rule that keeps nothing is refused, naming its flags.
  inputs_.selection.max_view_rms_px = 0.5;
  const std::string error =
      testing::InputErrorOf([&] { LoadCaptureTrainingData(inputs_, num_vertices()); });
  EXPECT_THAT(error, HasSubstr("--label-max-rms-px"));
  inputs_.selection.max_view_rms_px = 10;
  inputs_.selection.min_views = 1;
  EXPECT_THAT(
      testing::InputErrorOf([&] { LoadCaptureTrainingData(inputs_, num_vertices()); }),
      HasSubstr("--label-min-views"));
}

}  // namespace
}  // namespace handlabel
