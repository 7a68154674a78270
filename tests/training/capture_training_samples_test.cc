#include "training/capture_training_samples.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <set>

#include "capture/native_frame_source.h"
#include "capture/synth_capture.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "image/image_file.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

// A small synthetic capture on disk (DexYCB-like rig at 160 x 120, the simulated
// detector's 2D keypoints in detections/), read back as a native capture; its ground
// truth serves as the labels.
class CaptureSamplesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string dir = testing::ScratchDir() + "/capture";
    SynthCaptureOptions o;
    o.rig.preset = "dexycb";
    o.rig.width = 160;
    o.rig.height = 120;
    o.num_frames = 3;
    o.seed = 11;
    o.num_threads = 1;
    WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, dir, "builtin:capsule");
    source_ = std::make_unique<NativeFrameSource>(dir);
  }

  std::vector<LabeledFrame> TruthLabels() const {
    std::vector<LabeledFrame> labels;
    for (const std::string& id : source_->FrameIds()) {
      const FrameInput frame = source_->Load(id);
      labels.push_back({id, frame.ground_truth->keypoints, frame.ground_truth->vertices});
    }
    return labels;
  }

  std::unique_ptr<NativeFrameSource> source_;
};

CaptureSampleOptions StrongOptions() {
  CaptureSampleOptions o;
  o.crop_size = 64;
  o.seed = 5;
  o.augment.scale_sigma = 0.1;
  o.augment.noise_rect_probability = 0.5;
  o.shift_sigma = 0.1;
  return o;
}

// The 2D targets are the label's keypoints projected by the rig camera (its own
// projection, full-image pixels) and carried into the crop by the crop's scale and
// offset; the sample is cut from the frame whose label it carries.
TEST_F(CaptureSamplesTest, TargetsAreTheLabelProjectedIntoTheCrop) {
  const CaptureTrainingSamples samples(*source_, TruthLabels(), StrongOptions());
  ASSERT_EQ(samples.num_views(), 8);
  for (int64_t index : {0, 4, 7}) {
    const TrainingSample s = samples.Sample(index);
    const LabeledFrame& label = samples.frames()[s.frame];
    const Rig rig = source_->Load(label.id).rig;
    EXPECT_THAT(s.joints_3d,
                testing::MatrixNear(
                    TransformPoints(rig[0].cam_from_world, label.keypoints_3d), 1e-12));
    for (size_t v = 0; v < rig.size(); ++v) {
      const TrainingView& view = s.views[v];
      const Camera& cam = rig[v].camera;
      // The crop is a scaled, shifted copy of the image (fx = fy scaled alike).
      const double scale = view.intrinsics(0, 0) / cam.fx();
      EXPECT_NEAR(view.intrinsics(1, 1) / cam.fy(), scale, 1e-12);
      for (int k = 0; k < 21; ++k) {
        Eigen::Vector2d uv;
        ASSERT_TRUE(rig[v].ProjectWorld(label.keypoints_3d.row(k).transpose(), &uv));
        const Eigen::Vector2d in_crop(
            scale * (uv.x() - cam.cx()) + view.intrinsics(0, 2),
            view.intrinsics(1, 1) / cam.fy() * (uv.y() - cam.cy()) +
                view.intrinsics(1, 2));
        EXPECT_NEAR(view.joints_2d(k, 0), in_crop.x(), 1e-9) << "view " << v;
        EXPECT_NEAR(view.joints_2d(k, 1), in_crop.y(), 1e-9) << "view " << v;
        EXPECT_EQ(view.joints_2d_weight[k], 1.0f);
      }
      // master_from_cam carries the master frame's keypoints onto the same targets.
      const Eigen::Matrix4d cam_from_master = view.master_from_cam.inverse();
      for (int k = 0; k < 21; ++k) {
        const Eigen::Vector3d p =
            (cam_from_master * s.joints_3d.row(k).transpose().homogeneous()).head<3>();
        const Eigen::Vector3d uvw = view.intrinsics * p;
        EXPECT_NEAR(uvw.x() / uvw.z(), view.joints_2d(k, 0), 1e-6);
        EXPECT_NEAR(uvw.y() / uvw.z(), view.joints_2d(k, 1), 1e-6);
      }
    }
  }
}

// Without augmentation the crop's pixels are the source image where the crop
// intrinsics say: the pixels around the 2D targets show what the image shows at the
// label's projection.
TEST_F(CaptureSamplesTest, PlainCropPixelsAreTheImageSeenThroughTheCropIntrinsics) {
  CaptureSampleOptions o = StrongOptions();
  o.augment.enabled = false;
  const CaptureTrainingSamples samples(*source_, TruthLabels(), o);
  const TrainingSample s = samples.Sample(2);
  const FrameInput frame = source_->Load(samples.frames()[s.frame].id);
  const int S = o.crop_size;
  int compared = 0;
  for (size_t v = 0; v < frame.rig.size(); ++v) {
    const ImageU8 image = ReadImageFile(frame.image_paths[v]);
    const Camera& cam = frame.rig[v].camera;
    const TrainingView& view = s.views[v];
    for (int k = 0; k < 21; k += 4) {
      const int x = static_cast<int>(std::lround(view.joints_2d(k, 0)));
      const int y = static_cast<int>(std::lround(view.joints_2d(k, 1)));
      if (x < 0 || y < 0 || x >= S || y >= S) continue;
      // Crop pixel -> ray -> image pixel (the preset's cameras are pinhole).
      const Eigen::Vector3d ray = view.intrinsics.inverse() * Eigen::Vector3d(x, y, 1);
      const double u = cam.fx() * ray.x() / ray.z() + cam.cx();
      const double w = cam.fy() * ray.y() / ray.z() + cam.cy();
      const int u0 = static_cast<int>(std::floor(u)),
                w0 = static_cast<int>(std::floor(w));
      if (u0 < 0 || w0 < 0 || u0 + 1 >= image.width || w0 + 1 >= image.height) continue;
      const double au = u - u0, aw = w - w0;
      for (int c = 0; c < 3; ++c) {
        const double expected =
            (1 - aw) * ((1 - au) * image.at(u0, w0, c) + au * image.at(u0 + 1, w0, c)) +
            aw * ((1 - au) * image.at(u0, w0 + 1, c) + au * image.at(u0 + 1, w0 + 1, c));
        EXPECT_NEAR(view.image[(c * S + y) * S + x], expected / 255.0 - 0.5, 1e-5);
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, 20);
}

TEST_F(CaptureSamplesTest, SameIndexSameSampleAndEachEpochVisitsEveryFrameOnce) {
  const CaptureTrainingSamples a(*source_, TruthLabels(), StrongOptions());
  const CaptureTrainingSamples b(*source_, TruthLabels(), StrongOptions());
  const TrainingSample s1 = a.Sample(5), s2 = b.Sample(5), s3 = a.Sample(5);
  for (size_t v = 0; v < s1.views.size(); ++v) {
    EXPECT_EQ(s1.views[v].image, s2.views[v].image);
    EXPECT_EQ(s1.views[v].image, s3.views[v].image);
    EXPECT_EQ(s1.views[v].intrinsics, s2.views[v].intrinsics);
    EXPECT_EQ(s1.views[v].joints_2d, s2.views[v].joints_2d);
  }
  EXPECT_EQ(s1.joints_3d, s2.joints_3d);
  EXPECT_EQ(s1.vertices_3d, s2.vertices_3d);
  // Another index: other augmentation, even on the same frame.
  EXPECT_NE(a.Sample(6).views[1].image, s1.views[1].image);
  for (int64_t epoch = 0; epoch < 4; ++epoch) {
    std::set<size_t> seen;
    for (int64_t i = 3 * epoch; i < 3 * epoch + 3; ++i) seen.insert(a.FrameOfSample(i));
    EXPECT_EQ(seen, (std::set<size_t>{0, 1, 2})) << "epoch " << epoch;
  }
}

// Label windows with scale and shift jitter still hold every keypoint: side 2x the
// keypoint box, scaled by 1 +- 2 sigma, shifted by at most 2 sigma of the side.
TEST_F(CaptureSamplesTest, JitteredLabelWindowsHoldTheHand) {
  CaptureSampleOptions o = StrongOptions();
  o.detection_crop_probability = 0;
  const CaptureTrainingSamples samples(*source_, TruthLabels(), o);
  for (int64_t index = 0; index < 6; ++index) {
    for (const TrainingView& v : samples.Sample(index).views) {
      EXPECT_GE(v.joints_2d.minCoeff(), 0.0);
      EXPECT_LE(v.joints_2d.maxCoeff(), 64.0);
    }
  }
}

// With detections asked for, a view whose detections locate the hand is cropped around
// them (the window of CropFromKeypoints), else, as inference, it is the whole image at
// weight 0; label windows always count.
TEST_F(CaptureSamplesTest, WindowsComeFromDetectionsWhenTheyLocateTheHand) {
  const std::vector<LabeledFrame> labels = TruthLabels();
  FrameInput frame = source_->Load(labels[0].id);
  ASSERT_EQ(frame.keypoints_2d.size(), 8u);
  ASSERT_TRUE(frame.keypoints_2d[5].has_value());
  frame.keypoints_2d[5]->confidence.setZero();  // a view the detector missed
  HandCropOptions crop;
  crop.crop_size = 64;
  CaptureViewDraws from_detection;
  from_detection.from_detection = true;
  const CaptureViewDraws from_label;
  int located = 0;
  for (size_t v = 0; v < 8; ++v) {
    const CaptureViewCrop chosen =
        CaptureViewWindow(frame, v, labels[0].keypoints_3d, from_detection, crop);
    const CaptureViewCrop label =
        CaptureViewWindow(frame, v, labels[0].keypoints_3d, from_label, crop);
    EXPECT_EQ(label.weight, 1.0f);
    ASSERT_TRUE(frame.keypoints_2d[v].has_value());
    const std::optional<CropWindow> detected =
        CropFromKeypoints(*frame.keypoints_2d[v], crop);
    const CropWindow expected =
        detected ? *detected : WholeImageCrop(frame.rig[v].camera);
    located += detected.has_value();
    EXPECT_EQ(chosen.window.center, expected.center) << "view " << v;
    EXPECT_EQ(chosen.window.side, expected.side) << "view " << v;
    EXPECT_EQ(chosen.weight, detected ? 1.0f : 0.0f) << "view " << v;
  }
  EXPECT_GE(located, 4);  // the simulated detector finds the hand in most views
  EXPECT_LE(located, 7);  // not in view 5
}

// The capture with the detector's keypoints dropped in every view but view 0.
class OneDetectedView : public FrameSource {
 public:
  explicit OneDetectedView(const FrameSource& inner) : inner_(inner) {}
  std::vector<std::string> FrameIds() const override { return inner_.FrameIds(); }
  FrameInput Load(const std::string& id) const override {
    FrameInput frame = inner_.Load(id);
    for (size_t v = 1; v < frame.keypoints_2d.size(); ++v) {
      if (frame.keypoints_2d[v]) frame.keypoints_2d[v]->confidence.setZero();
    }
    return frame;
  }
  std::string Describe() const override { return "one detected view"; }

 private:
  const FrameSource& inner_;
};

// A frame whose detections locate the hand in fewer than two views cannot be
// triangulated (inference fits it instead): its views take the label windows and all
// count; with two or more, the views the detector missed weigh 0.
TEST_F(CaptureSamplesTest, FramesWithoutTwoDetectedViewsFallBackToLabelWindows) {
  CaptureSampleOptions o = StrongOptions();
  o.detection_crop_probability = 1;
  o.augment.enabled = false;
  const OneDetectedView one_view(*source_);
  const CaptureTrainingSamples samples(one_view, TruthLabels(), o);
  const FrameInput frame = one_view.Load(TruthLabels()[0].id);
  ASSERT_TRUE(CropFromKeypoints(*frame.keypoints_2d[0], HandCropOptions()).has_value());
  for (int64_t index = 0; index < 3; ++index) {
    for (const TrainingView& v : samples.Sample(index).views) {
      EXPECT_EQ(v.view_weight, 1.0f);
      EXPECT_GE(v.joints_2d.minCoeff(), 0.0);  // a label window holds the hand
      EXPECT_LE(v.joints_2d.maxCoeff(), 64.0);
    }
  }
}

// The missed share counts the views inference would cut whole at weight 0: with the
// detections of every view but view 0 emptied, 7 of 8 in every frame.
TEST_F(CaptureSamplesTest, MissedViewShareCountsViewsTheDetectionsDoNotLocate) {
  const OneDetectedView one_view(*source_);
  CaptureSampleOptions o = StrongOptions();
  const CaptureTrainingSamples samples(one_view, TruthLabels(), o);
  HandCropOptions crop;
  crop.crop_size = o.crop_size;
  for (const LabeledFrame& label : TruthLabels()) {
    ASSERT_TRUE(CropFromKeypoints(*one_view.Load(label.id).keypoints_2d[0], crop))
        << label.id;
  }
  EXPECT_DOUBLE_EQ(samples.MissedViewShare(), 7.0 / 8.0);
  const CaptureTrainingSamples all_views(*source_, TruthLabels(), o);
  EXPECT_LT(all_views.MissedViewShare(), 0.5);  // the simulated detector finds most
}

TEST_F(CaptureSamplesTest, BadOptionsAndLabelsNameTheField) {
  CaptureSampleOptions o = StrongOptions();
  o.augment.rotation_probability = 0.5;
  EXPECT_THAT(testing::InputErrorOf([&] { o.Check("opts"); }),
              HasSubstr("augment.rotation_probability"));
  o = StrongOptions();
  o.detection_crop_probability = 1.5;
  EXPECT_THAT(testing::InputErrorOf([&] { o.Check("opts"); }),
              HasSubstr("detection_crop_probability"));
  o = StrongOptions();
  o.crop_size = 100;
  EXPECT_THAT(testing::InputErrorOf([&] { o.Check("opts"); }), HasSubstr("crop_size"));

  EXPECT_THAT(testing::InputErrorOf(
                  [&] { (void)CaptureTrainingSamples(*source_, {}, StrongOptions()); }),
              HasSubstr("labelled frames"));
  std::vector<LabeledFrame> labels = TruthLabels();
  labels[1].keypoints_3d(3, 2) = std::nan("");
  const std::string error = testing::InputErrorOf(
      [&] { (void)CaptureTrainingSamples(*source_, labels, StrongOptions()); });
  EXPECT_THAT(error, HasSubstr("keypoints_3d"));
  EXPECT_THAT(error, HasSubstr(labels[1].id));
}

}  // namespace
}  // namespace handlabel
