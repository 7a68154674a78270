#include "capture/synth_appearance.h"

#include <gtest/gtest.h>

#include "capture/synth_capture.h"
#include "core/data_dir.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "hand/hand_model_io.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

SynthCaptureOptions SmallOptions(SynthAppearance appearance) {
  SynthCaptureOptions o;
  o.rig.preset = "dexycb";
  o.rig.width = 160;
  o.rig.height = 120;
  o.num_frames = 2;
  o.seed = 5;
  o.scene.objects = true;
  o.num_threads = 1;
  o.view.appearance = appearance;
  return o;
}

HandModel OpenHand() { return LoadHandModel(ShippedModelPath("open_hand_right.npz")); }

// The realistic look changes pixels only: the same scene and ground truth, the hand
// mask a subset of the basic one (forearm and table may hide hand pixels, never add
// any), object masks without the scenery.
TEST(SynthAppearance, RealisticKeepsTheSceneAndTheGroundTruth) {
  const HandModel model = OpenHand();
  const SynthCaptureOptions basic_options = SmallOptions(SynthAppearance::kBasic);
  const SynthCaptureOptions real_options = SmallOptions(SynthAppearance::kRealistic);
  const Rig rig = MakePresetRig(basic_options.rig, basic_options.seed);
  const SynthGenerator basic(model, rig, basic_options), real(model, rig, real_options);
  for (int f = 0; f < 2; ++f) {
    const SynthFrame a = basic.Generate(f), b = real.Generate(f);
    EXPECT_EQ(a.scene.params.hand_pose, b.scene.params.hand_pose);
    EXPECT_EQ(a.scene.hand.keypoints, b.scene.hand.keypoints);
    EXPECT_EQ(a.scene.objects.size(), b.scene.objects.size());
    EXPECT_TRUE(a.scene.scenery.empty());
    ASSERT_EQ(b.scene.scenery.size(), 2u);  // forearm and table
    for (size_t c = 0; c < a.views.size(); ++c) {
      const SynthView& va = a.views[c];
      const SynthView& vb = b.views[c];
      EXPECT_EQ(va.keypoints, vb.keypoints);
      EXPECT_NE(va.rgb.data, vb.rgb.data);
      int extra_hand = 0, extra_object = 0, scenery_pixels = 0;
      for (size_t i = 0; i < va.hand_mask.data.size(); ++i) {
        extra_hand += vb.hand_mask.data[i] == 255 && va.hand_mask.data[i] != 255;
        extra_object += vb.object_mask.data[i] != 0 &&
                        vb.object_mask.data[i] != va.object_mask.data[i];
        scenery_pixels += vb.hand_mask.data[i] == 0 && vb.object_mask.data[i] == 0;
      }
      EXPECT_EQ(extra_hand, 0) << "camera " << c;
      EXPECT_EQ(extra_object, 0) << "camera " << c;
      EXPECT_GT(scenery_pixels, 0);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        // Scenery can only hide keypoints.
        if (va.visibility[k] != kVisible) {
          EXPECT_NE(vb.visibility[k], kVisible);
        }
      }
    }
  }
}

// The forearm continues the wrist away from the fingers.
TEST(SynthAppearance, ForearmStartsAtTheWristAndPointsAwayFromTheFingers) {
  const HandModel model = OpenHand();
  const SynthCaptureOptions o = SmallOptions(SynthAppearance::kRealistic);
  const SynthGenerator generator(model, MakePresetRig(o.rig, o.seed), o);
  for (int f = 0; f < 3; ++f) {
    const SynthScene scene = generator.Generate(f).scene;
    const RenderMesh& arm = scene.scenery[0];
    const Eigen::Vector3d wrist = scene.hand.keypoints.row(0).transpose();
    const Eigen::Vector3d mcp = scene.hand.keypoints.row(9).transpose();
    // First ring (24 vertices): its centre lies within 2 cm of the wrist.
    const Eigen::Vector3d first = arm.vertices.topRows(24).colwise().mean().transpose();
    EXPECT_LT((first - wrist).norm(), 0.02) << "frame " << f;
    // Farthest point: about forearm_length from the wrist, on the side away from the
    // middle finger's knuckle.
    Eigen::Index far = 0;
    (arm.vertices.rowwise() - wrist.transpose()).rowwise().norm().maxCoeff(&far);
    const Eigen::Vector3d end = arm.vertices.row(far).transpose();
    EXPECT_NEAR((end - wrist).norm(), o.view.realistic.forearm_length, 0.06);
    EXPECT_LT((end - wrist).normalized().dot((mcp - wrist).normalized()), -0.9);
  }
}

// The key light comes down from `up` at 40-80 degrees of elevation and the fill at
// 10-40, whichever way the world's up points; a direction the table cannot stand on,
// or none, is refused by name.
TEST(SynthAppearance, LightsComeDownFromTheGivenUp) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const std::vector<Eigen::Vector3d> ups = {
      Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 0, 0.01),
      Eigen::Vector3d(0.3, -2, 0.5)};
  std::vector<std::vector<uint8_t>> pixels;
  for (const Eigen::Vector3d& up : ups) {
    SynthCaptureOptions o = SmallOptions(SynthAppearance::kRealistic);
    o.view.realistic.up = up;
    o.view.realistic.table = up == Eigen::Vector3d::UnitZ();
    const SynthGenerator generator(model, MakePresetRig(o.rig, o.seed), o);
    for (int frame = 0; frame < 2; ++frame) {
      const SynthFrame f = generator.Generate(frame);
      const auto& lights = f.scene.lighting.lights;
      ASSERT_EQ(lights.size(), 2u);
      const double key_elevation = -lights[0].direction_in_world.dot(up.normalized());
      const double fill_elevation = -lights[1].direction_in_world.dot(up.normalized());
      EXPECT_NEAR(lights[0].direction_in_world.norm(), 1, 1e-12);
      EXPECT_GE(key_elevation, std::sin(40 * M_PI / 180) - 1e-12) << up.transpose();
      EXPECT_LE(key_elevation, std::sin(80 * M_PI / 180) + 1e-12) << up.transpose();
      EXPECT_GE(fill_elevation, std::sin(10 * M_PI / 180) - 1e-12) << up.transpose();
      EXPECT_LE(fill_elevation, std::sin(40 * M_PI / 180) + 1e-12) << up.transpose();
      if (frame == 0) pixels.push_back(f.views[3].rgb.data);
    }
  }
  EXPECT_NE(pixels[0], pixels[1]) << "lit from below, the hand must look different";
  SynthViewOptions view;
  view.appearance = SynthAppearance::kRealistic;
  view.realistic.up = -Eigen::Vector3d::UnitZ();
  EXPECT_EQ(testing::InputErrorOf([&] { view.Check("v"); }),
            "realistic look options: field 'table': expected off unless up is +z (the "
            "table is the plane z = table_height)");
  view.realistic.table = false;
  view.realistic.up = Eigen::Vector3d::Zero();
  EXPECT_EQ(testing::InputErrorOf([&] { view.Check("v"); }),
            "realistic look options: field 'up': expected a finite direction of non-zero "
            "length");
}

TEST(SynthAppearance, DeterministicAndNamed) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const SynthCaptureOptions o = SmallOptions(SynthAppearance::kRealistic);
  const SynthGenerator generator(model, MakePresetRig(o.rig, o.seed), o);
  EXPECT_EQ(generator.Generate(1).views[3].rgb.data,
            generator.Generate(1).views[3].rgb.data);
  EXPECT_EQ(SynthAppearanceFromName("realistic", "f", "appearance"),
            SynthAppearance::kRealistic);
  EXPECT_EQ(SynthAppearanceName(SynthAppearance::kBasic), "basic");
  EXPECT_EQ(testing::InputErrorOf([] { SynthAppearanceFromName("fancy", "f", "x"); }),
            "f: field 'x': expected basic | realistic, got 'fancy'");
  EXPECT_EQ(SynthOptionsToJson(o)["view"]["appearance"], "realistic");
  EXPECT_FALSE(SynthOptionsToJson(SmallOptions(SynthAppearance::kBasic))["view"].contains(
      "appearance"));
}

}  // namespace
}  // namespace handlabel
