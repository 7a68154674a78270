#include "training/training_samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "capture/rig_presets.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "network/poem/hand_crop.h"
#include "tests/reference_values.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

SynthCaptureOptions SmallSynth(uint64_t seed) {
  SynthCaptureOptions o;
  o.rig.preset = "dexycb";
  o.rig.width = 320;  // intrinsics scaled: fx != fy is fine, crops stay square-pixel
  o.rig.height = 200;
  o.seed = seed;
  return o;
}

TrainingSampleOptions StrongAugmentation() {
  TrainingSampleOptions o;
  o.crop_size = 64;
  o.augment.rotation_probability = 1.0;
  o.augment.rotation_sigma_deg = 30.0;
  o.augment.scale_sigma = 0.1;
  o.augment.noise_rect_probability = 0.5;
  return o;
}

// The 3D targets seen through each view's (augmented) extrinsic and crop intrinsics
// land exactly on the 2D targets, whatever the rotation folded into the extrinsic.
TEST(TrainingSamples, FoldedAugmentationKeepsProjectionsOnThe2dTargets) {
  const SynthTrainingSamples source(MakeCapsuleHand(HandSide::kRight), SmallSynth(3),
                                    StrongAugmentation());
  for (int64_t index : {0, 5}) {
    const TrainingSample s = source.Sample(index);
    ASSERT_EQ(s.views.size(), 8u);
    EXPECT_TRUE(s.views[0].master_from_cam.isIdentity(0));
    for (const TrainingView& v : s.views) {
      EXPECT_DOUBLE_EQ(v.intrinsics(0, 0), v.intrinsics(1, 1));  // square pixels
      EXPECT_EQ(v.intrinsics(0, 1), 0.0);                        // no skew
      const Eigen::Matrix4d cam_from_master = v.master_from_cam.inverse();
      EXPECT_NEAR((v.master_from_cam.topLeftCorner<3, 3>().determinant()), 1.0, 1e-12);
      for (int k = 0; k < 21; ++k) {
        const Eigen::Vector3d p =
            (cam_from_master * s.joints_3d.row(k).transpose().homogeneous()).head<3>();
        const Eigen::Vector3d uvw = v.intrinsics * p;
        EXPECT_NEAR(uvw.x() / uvw.z(), v.joints_2d(k, 0), 1e-6);
        EXPECT_NEAR(uvw.y() / uvw.z(), v.joints_2d(k, 1), 1e-6);
      }
    }
  }
}

// The crop masks (the mask head's targets) cover exactly where the true hand lands:
// the vertices projected through each view's crop camera fall on the mask, and the
// mask stays inside the box of those projections. A mask warped differently from the
// image (transposed, unrotated, from another view) fails both.
TEST(TrainingSamples, CropMasksCoverTheProjectedHand) {
  TrainingSampleOptions o = StrongAugmentation();
  o.masks = true;
  SynthCaptureOptions synth = SmallSynth(6);
  synth.scene.objects = false;  // the masks are the visible hand: nothing in front
  const SynthTrainingSamples source(MakeCapsuleHand(HandSide::kRight), synth, o);
  const int S = o.crop_size;
  for (int64_t index : {0, 3}) {
    const TrainingSample s = source.Sample(index);
    for (const TrainingView& v : s.views) {
      ASSERT_EQ(v.mask.size(), static_cast<size_t>(S * S));
      auto on = [&](int x, int y) {  // within a pixel of a mask pixel
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < S && yy < S && v.mask[yy * S + xx] > 0.5f)
              return true;
          }
        return false;
      };
      const Eigen::Matrix4d cam_from_master = v.master_from_cam.inverse();
      Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e9), hi = -lo;
      int inside = 0, on_mask = 0;
      for (int i = 0; i < s.vertices_3d.rows(); ++i) {
        const Eigen::Vector3d p =
            (cam_from_master * s.vertices_3d.row(i).transpose().homogeneous()).head<3>();
        const Eigen::Vector3d uvw = v.intrinsics * p;
        const Eigen::Vector2d uv = uvw.head<2>() / uvw.z();
        lo = lo.cwiseMin(uv);
        hi = hi.cwiseMax(uv);
        // Pixel centres are at integer coordinates.
        const int x = static_cast<int>(std::lround(uv.x())),
                  y = static_cast<int>(std::lround(uv.y()));
        if (x < 0 || y < 0 || x >= S || y >= S) continue;
        ++inside;
        on_mask += on(x, y);
      }
      ASSERT_GT(inside, 100);
      EXPECT_GE(on_mask, 0.98 * inside) << "sample " << index;
      int mask_pixels = 0, in_box = 0;
      for (int y = 0; y < S; ++y)
        for (int x = 0; x < S; ++x) {
          if (v.mask[y * S + x] <= 0.5f) continue;
          ++mask_pixels;
          in_box += x >= lo.x() - 1.5 && x <= hi.x() + 1.5 && y >= lo.y() - 1.5 &&
                    y <= hi.y() + 1.5;
        }
      ASSERT_GT(mask_pixels, 50);
      EXPECT_EQ(in_box, mask_pixels) << "sample " << index;
    }
  }
}

// Crops around the 2D box (side 2x the box) hold every keypoint, even after scale and
// rotation jitter; without augmentation the box is centred.
TEST(TrainingSamples, CropsHoldTheHand) {
  const SynthTrainingSamples augmented(MakeCapsuleHand(HandSide::kRight), SmallSynth(4),
                                       StrongAugmentation());
  TrainingSampleOptions plain = StrongAugmentation();
  plain.augment.enabled = false;
  const SynthTrainingSamples clean(MakeCapsuleHand(HandSide::kRight), SmallSynth(4),
                                   plain);
  for (const SynthTrainingSamples* src : {&augmented, &clean}) {
    const TrainingSample s = src->Sample(2);
    for (const TrainingView& v : s.views) {
      if (v.joints_2d_weight[0] == 0) continue;
      EXPECT_GE(v.joints_2d.minCoeff(), 0.0);
      EXPECT_LE(v.joints_2d.maxCoeff(), 64.0);
    }
  }
  const TrainingSample s = clean.Sample(2);
  for (const TrainingView& v : s.views) {
    const Eigen::Vector2d lo = v.joints_2d.colwise().minCoeff(),
                          hi = v.joints_2d.colwise().maxCoeff();
    EXPECT_NEAR(0.5 * (lo + hi).x(), 32.0, 1e-6);
    EXPECT_NEAR(std::max(hi.x() - lo.x(), hi.y() - lo.y()), 32.0, 1e-6);
  }
}

TEST(TrainingSamples, SameIndexSameSampleAndReuseGroups) {
  TrainingSampleOptions o = StrongAugmentation();
  o.frame_reuse = 3;
  o.reuse_group = 2;
  const SynthTrainingSamples a(MakeCapsuleHand(HandSide::kRight), SmallSynth(5), o);
  const SynthTrainingSamples b(MakeCapsuleHand(HandSide::kRight), SmallSynth(5), o);
  const TrainingSample s1 = a.Sample(7), s2 = b.Sample(7), s3 = a.Sample(7);
  EXPECT_EQ(s1.views[3].image, s2.views[3].image);
  EXPECT_EQ(s1.views[3].image, s3.views[3].image);
  EXPECT_EQ(s1.joints_3d, s2.joints_3d);
  // Samples 0, 1 | 2, 3 | 4, 5 use frames 0, 1; samples 6, 7 use frames 2, 3.
  const std::vector<int64_t> frames = {0, 1, 0, 1, 0, 1, 2, 3};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(TrainingFrameOf(i, o), frames[i]) << i;
  EXPECT_EQ(a.Sample(2).frame, 0);
  EXPECT_NE(a.Sample(2).views[1].image, a.Sample(0).views[1].image);  // new augmentation
}

TEST(TrainingSamples, ImagesAreNormalisedAndGainStaysInRange) {
  const SynthTrainingSamples source(MakeCapsuleHand(HandSide::kRight), SmallSynth(6),
                                    StrongAugmentation());
  const TrainingSample s = source.Sample(1);
  for (const TrainingView& v : s.views) {
    ASSERT_EQ(v.image.size(), 3u * 64 * 64);
    for (float x : v.image) {
      ASSERT_GE(x, -0.5f);
      ASSERT_LE(x, 0.5f);
    }
  }
}

// Two samples' crops, masks, cameras and targets (rotation, scale, gain and noise
// rectangles all drawn).
testing::ReferenceValues TrainingSampleValues() {
  TrainingSampleOptions o = StrongAugmentation();
  o.masks = true;
  o.augment.noise_rect_probability = 1.0;
  const SynthTrainingSamples source(MakeCapsuleHand(HandSide::kRight), SmallSynth(9), o);
  testing::ReferenceValues values("training_samples_two");
  for (int64_t index : {0, 3}) {
    const TrainingSample s = source.Sample(index);
    const std::string at = "sample" + std::to_string(index);
    values.Exact(at + ".index", s.index).Exact(at + ".frame", s.frame);
    values.Near(at + ".joints_3d", s.joints_3d).Near(at + ".vertices_3d", s.vertices_3d);
    for (size_t k = 0; k < s.views.size(); ++k) {
      const TrainingView& v = s.views[k];
      const std::string view = at + ".view" + std::to_string(k);
      values.Near(view + ".image", v.image).Near(view + ".mask", v.mask);
      values.Near(view + ".intrinsics", v.intrinsics);
      values.Near(view + ".master_from_cam", v.master_from_cam);
      values.Near(view + ".joints_2d", v.joints_2d);
      values.Near(
          view + ".joints_2d_weight",
          std::vector<float>(v.joints_2d_weight.begin(), v.joints_2d_weight.end()));
    }
  }
  return values;
}

// The same bits when sampled twice, and tests/data/reference/training_samples_two.txt
// within 1e-5 of each array's scale (renders and augmentation go through libm, whose
// variants differ in the last bits between CPUs; one pixel rounded to the other 8-bit
// level moves a 64x64 crop's sums by about 1.3e-6 of their scale).
// A view cut as a missed detection is what inference cuts where the detections miss:
// the whole image through network/poem/hand_crop.h (a second implementation of the
// crop), at view weight 0, with its targets still on the projections; the others stay
// hand crops at weight 1.
TEST(TrainingSamples, MissedViewsAreTheWholeImageAtWeightZero) {
  const SynthCaptureOptions synth = SmallSynth(3);
  // Square pixels (fx = fy), as synthetic crops have them, so that hand_crop.h's
  // window (which keeps fx and fy) is the same crop.
  const Rig preset = MakePresetRig(synth.rig, synth.seed);
  Rig rig;
  for (const RigCamera& c : preset.cameras()) {
    RigCamera square = c;
    const double f = 0.5 * (c.camera.fx() + c.camera.fy());
    square.camera = Camera::Pinhole(f, f, c.camera.cx(), c.camera.cy(), c.camera.width(),
                                    c.camera.height());
    rig.Add(square);
  }
  TrainingSampleOptions o;
  o.crop_size = 64;
  o.augment.enabled = false;
  o.view_dropout = 0.5;
  const SynthTrainingSamples source(MakeCapsuleHand(HandSide::kRight), rig, synth, o);
  const SynthFrame frame = source.generator().Generate(0);
  int missed_seen = 0;
  for (int64_t index = 0; index < 4; ++index) {
    const TrainingSample s = source.Sample(index);
    int weighted = 0;
    for (size_t c = 0; c < s.views.size(); ++c) {
      const TrainingView& v = s.views[c];
      weighted += v.view_weight == 1.0f;
      if (v.view_weight != 0.0f) continue;
      ++missed_seen;
      if (s.frame != 0) continue;
      const RigCamera& cam = source.generator().rig()[c];
      const CropWindow whole = WholeImageCrop(cam.camera);
      const Eigen::Matrix3d K = CropIntrinsics(cam.camera, whole, o.crop_size);
      EXPECT_NEAR((v.intrinsics - K).norm(), 0, 1e-9) << "view " << c;
      HandCropOptions crop;
      crop.crop_size = o.crop_size;
      const ImageU8& rgb = frame.views[c].rgb;
      const std::vector<float> expected =
          WarpCrop({rgb.width, rgb.height, rgb.data.data()}, cam.camera, whole, crop);
      ASSERT_EQ(v.image.size(), expected.size());
      double worst = 0;
      for (size_t i = 0; i < expected.size(); ++i) {
        worst = std::max(worst, std::abs(double{v.image[i]} - expected[i]));
      }
      EXPECT_LT(worst, 1e-4) << "view " << c;
    }
    EXPECT_GE(weighted, 2) << "sample " << index;
  }
  EXPECT_GT(missed_seen, 0);
}

// Views go missing at the asked rate (a little less: two views always stay), never
// below two weighted views, and not at all at rate 0.
TEST(TrainingSamples, MissedViewsComeAtTheirRate) {
  std::mt19937_64 rng(5);
  int64_t missed = 0, views = 0;
  for (int i = 0; i < 4000; ++i) {
    const std::vector<bool> m = DrawMissedViews(0.3, 8, rng);
    int kept = 0;
    for (bool x : m) kept += !x;
    ASSERT_GE(kept, 2);
    missed += 8 - kept;
    views += 8;
  }
  EXPECT_NEAR(static_cast<double>(missed) / views, 0.3, 0.02);
  for (int i = 0; i < 100; ++i) {
    const std::vector<bool> all = DrawMissedViews(1.0, 5, rng);
    EXPECT_EQ(std::count(all.begin(), all.end(), false), 2);
    const std::vector<bool> two = DrawMissedViews(1.0, 2, rng);
    EXPECT_EQ(std::count(two.begin(), two.end(), true), 0);
  }
  std::mt19937_64 untouched(9), reference(9);
  EXPECT_EQ(DrawMissedViews(0.0, 8, untouched), std::vector<bool>(8, false));
  EXPECT_EQ(untouched(), reference());
}

TEST(TrainingSamples, SameIndexKeepsItsSample) {
  const testing::ReferenceValues first = TrainingSampleValues();
  EXPECT_EQ(first.Bits(), TrainingSampleValues().Bits());
  EXPECT_TRUE(first.Compare(1e-9, 1e-5));
}

TEST(TrainingSamples, OptionsRejectBadValues) {
  TrainingSampleOptions o;
  o.crop_size = 100;
  EXPECT_THROW(o.Check("test"), InputError);
  o = TrainingSampleOptions();
  o.augment.gain_min = 1.5;
  EXPECT_THROW(o.Check("test"), InputError);
  o = TrainingSampleOptions();
  o.view_dropout = 1.5;
  EXPECT_EQ(testing::InputErrorOf([&] { o.Check("test"); }),
            "test: field 'view_dropout': expected 0..1, got 1.5");
}

}  // namespace
}  // namespace handlabel
