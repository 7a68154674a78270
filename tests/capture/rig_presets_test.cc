#include "capture/rig_presets.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

TEST(RigPresets, PresetsMimicTheDatasets) {
  struct Expect {
    const char* preset;
    size_t cameras;
    int width, height;
  };
  for (const Expect& e : {Expect{"dexycb", 8, 640, 480}, Expect{"oakink", 4, 848, 480},
                          Expect{"ho3d", 5, 640, 480}}) {
    RigPresetOptions o;
    o.preset = e.preset;
    const Rig rig = MakePresetRig(o, 0);
    ASSERT_EQ(rig.size(), e.cameras) << e.preset;
    for (const RigCamera& cam : rig.cameras()) {
      EXPECT_EQ(cam.camera.width(), e.width);
      EXPECT_EQ(cam.camera.height(), e.height);
      EXPECT_NEAR(cam.camera.fx(), 612, 8) << e.preset;
      // The workspace centre is near the image centre of every camera.
      Eigen::Vector2d uv;
      ASSERT_TRUE(cam.ProjectWorld(Eigen::Vector3d::Zero(), &uv));
      EXPECT_NEAR(uv.x(), e.width / 2.0, 0.1 * e.width) << e.preset << " " << cam.name;
      EXPECT_NEAR(uv.y(), e.height / 2.0, 0.1 * e.height) << e.preset << " " << cam.name;
      // Cameras look down at the table from above.
      EXPECT_GT(cam.CenterInWorld().z(), 0.1);
    }
    // Presets do not depend on the seed.
    EXPECT_EQ(MakePresetRig(o, 5)[1].camera.params(), rig[1].camera.params());
  }
}

// The full-body studio: HD views with lens distortion, cameras metres away, so a hand
// at the workspace centre is small (docs/detector.md, "Small hands"), off the image
// centre (the cameras aim at the body) and inside every view.
TEST(RigPresets, StudioFilmsASmallHandInDistortedHdViews) {
  RigPresetOptions o;
  o.preset = "studio";
  const Rig rig = MakePresetRig(o, 0);
  ASSERT_EQ(rig.size(), 5u);
  for (const RigCamera& cam : rig.cameras()) {
    EXPECT_EQ(cam.camera.width(), 1920);
    EXPECT_EQ(cam.camera.height(), 1080);
    EXPECT_EQ(cam.camera.model(), CameraModelId::kOpenCV);
    const double distance = cam.CenterInWorld().norm();
    EXPECT_GE(distance, 2.5) << cam.name;
    EXPECT_LE(distance, 4.0) << cam.name;
    // An 18 cm hand across the view direction at the workspace centre.
    Eigen::Vector2d a, b;
    const Eigen::Vector3d across =
        0.09 * (cam.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitX());
    ASSERT_TRUE(cam.ProjectWorld(-across, &a));
    ASSERT_TRUE(cam.ProjectWorld(across, &b));
    EXPECT_GT((b - a).norm(), 55) << cam.name;
    EXPECT_LT((b - a).norm(), 110) << cam.name;
    EXPECT_TRUE(cam.camera.InImage((a + b) / 2)) << cam.name;
    EXPECT_GT(((a + b) / 2 - Eigen::Vector2d(960, 540)).norm(), 50) << cam.name;
  }
}

TEST(RigPresets, SizeScalesIntrinsicsAndKeepsTheFieldOfView) {
  RigPresetOptions o;
  const Rig native = MakePresetRig(o, 0);
  o.width = 320;
  o.height = 240;
  const Rig half = MakePresetRig(o, 0);
  for (size_t i = 0; i < native.size(); ++i) {
    EXPECT_EQ(half[i].camera.width(), 320);
    // A world point lands at the same relative position.
    const Eigen::Vector3d p(0.03, -0.02, 0.05);
    Eigen::Vector2d a, b;
    ASSERT_TRUE(native[i].ProjectWorld(p, &a));
    ASSERT_TRUE(half[i].ProjectWorld(p, &b));
    EXPECT_NEAR((b.x() + 0.5) * 2, a.x() + 0.5, 1e-9);
    EXPECT_NEAR((b.y() + 0.5) * 2, a.y() + 0.5, 1e-9);
  }
}

TEST(RigPresets, RandomRigsDependOnTheSeedOnly) {
  RigPresetOptions o;
  o.preset = "random";
  o.num_cameras = 7;
  o.distortion = true;
  const Rig a = MakePresetRig(o, 3), b = MakePresetRig(o, 3), c = MakePresetRig(o, 4);
  ASSERT_EQ(a.size(), 7u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].camera.params(), b[i].camera.params());
    EXPECT_TRUE(a[i].camera.HasDistortion());
    const double distance = a[i].CenterInWorld().norm();
    EXPECT_GE(distance, 0.5 - 0.05);
    EXPECT_LE(distance, 1.0 + 0.05);
    // Horizontal field of view within the requested range.
    const double fov =
        2 * std::atan(0.5 * a[i].camera.width() / a[i].camera.fx()) * 180 / M_PI;
    EXPECT_GE(fov, 49.9);
    EXPECT_LE(fov, 75.1);
  }
  EXPECT_NE(a[0].camera.params(), c[0].camera.params());
}

TEST(RigPresets, BadOptionsNameTheField) {
  RigPresetOptions o;
  o.width = 100;  // height missing
  try {
    o.Check("test");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "size");
  }
  o = RigPresetOptions();
  o.preset = "random";
  o.num_cameras = 0;
  EXPECT_THROW(MakePresetRig(o, 0), InputError);
}

}  // namespace
}  // namespace handlabel
