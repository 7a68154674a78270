// The HO3D v3 multi-camera frame source against a fixture written in HO3D's layout from
// a synthetic capture (calibration files, rgb/<fid>.jpg and meta/<fid>.pkl per camera
// folder), and against a meta pickle written by numpy (tests/data/ho3d).
#include "capture/ho3d_frame_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "capture/synth_capture.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "image/image_file.h"
#include "tests/capture/ho3d_fixture.h"
#include "tests/hand/mano_sized_model.h"  // Py2PickleWriter
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using namespace testing;  // the fixture

TEST(Ho3dFrameSource, LoadsTheRigImagesAndTruthThatWereWritten) {
  const Ho3dFixture fx = WriteHo3dFixture(testing::ScratchDir());
  const Ho3dFrameSource source(fx.split + "/ABF1");
  EXPECT_EQ(source.FrameIds(), (std::vector<std::string>{"0000", "0001"}));
  EXPECT_EQ(source.side(), HandSide::kRight);
  EXPECT_THAT(source.Describe(), HasSubstr("3 cameras, 2 frames"));
  for (int f = 0; f < 2; ++f) {
    const FrameInput frame = source.Load(Fid(f));
    ASSERT_EQ(frame.rig.size(), 3u);
    EXPECT_TRUE(frame.keypoints_2d.empty());
    EXPECT_TRUE(frame.mask_paths.empty());
    for (size_t v = 0; v < 3; ++v) {
      EXPECT_EQ(frame.rig[v].name, fx.rig[v].name);
      for (int i = 0; i < 4; ++i) {
        EXPECT_NEAR(frame.rig[v].camera.params()[i], fx.rig[v].camera.params()[i], 1e-12);
      }
      EXPECT_THAT(frame.rig[v].cam_from_world,
                  testing::Rigid3Near(fx.rig[v].cam_from_world, 1e-12, 1e-12));
      EXPECT_EQ(frame.image_paths[v],
                fx.split + "/" + fx.rig[v].name + "/rgb/" + Fid(f) + ".jpg");
      const ImageU8 image = ReadImageFile(frame.image_paths[v]);
      const ImageU8& rendered = fx.frames[f].views[v].rgb;
      ASSERT_EQ(image.data.size(), rendered.data.size());
      int worst = 0;
      for (size_t i = 0; i < image.data.size(); ++i)
        worst = std::max(worst, std::abs(int(image.data[i]) - int(rendered.data[i])));
      EXPECT_LE(worst, 6);
    }
    ASSERT_TRUE(frame.ground_truth.has_value());
    // float32 in the pickles
    EXPECT_THAT(frame.ground_truth->keypoints,
                testing::MatrixNear(fx.frames[f].scene.hand.keypoints, 1e-6));
    EXPECT_EQ(frame.ground_truth->vertices.rows(), 0);
  }
}

TEST(Ho3dFrameSource, TruthFromTheFirstCameraWithFullJoints) {
  const Ho3dFixture fx = WriteHo3dFixture(testing::ScratchDir(), 1);
  // Evaluation-split style: only the root joint. Then camera 1's joints are used.
  testing::Py2PickleWriter w;
  const float root_joint[3] = {0.f, 0.f, -0.5f};
  w.Proto();
  w.BeginDict();
  w.Str("handJoints3D");
  w.Array({3}, "f4", root_joint, 12);
  w.EndDict();
  std::ofstream(fx.split + "/" + fx.rig[0].name + "/meta/0000.pkl", std::ios::binary)
      << w.Finish();
  FrameInput frame = Ho3dFrameSource(fx.split + "/ABF1").Load("0000");
  ASSERT_TRUE(frame.ground_truth.has_value());
  EXPECT_THAT(frame.ground_truth->keypoints,
              testing::MatrixNear(fx.frames[0].scene.hand.keypoints, 1e-6));
  // Without any meta file there is no truth.
  for (const RigCamera& camera : fx.rig.cameras())
    fs::remove_all(fx.split + "/" + camera.name + "/meta");
  frame = Ho3dFrameSource(fx.split + "/ABF1").Load("0000");
  EXPECT_FALSE(frame.ground_truth.has_value());
}

TEST(Ho3dFrameSource, NumpyWrittenMetaGivesOpenCvAxesAndSnapOrder) {
  const Ho3dFixture fx = WriteHo3dFixture(testing::ScratchDir(), 1);
  for (const RigCamera& camera : fx.rig.cameras())
    fs::remove_all(fx.split + "/" + camera.name + "/meta");
  const std::string meta = fx.split + "/" + fx.rig[1].name + "/meta";
  fs::create_directories(meta);
  fs::copy_file(kData + "/meta_0000.pkl", meta + "/0000.pkl");
  const FrameInput frame = Ho3dFrameSource(fx.split + "/ABF1").Load("0000");
  ASSERT_TRUE(frame.ground_truth.has_value());
  std::ifstream in(kData + "/expected.json");
  const nlohmann::json expected = nlohmann::json::parse(in)["keypoints_in_camera_snap"];
  Points3d in_camera(kNumHandKeypoints, 3);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    for (int c = 0; c < 3; ++c) in_camera(k, c) = expected[k][c].get<double>();
  }
  EXPECT_THAT(frame.ground_truth->keypoints,
              testing::MatrixNear(
                  TransformPoints(fx.rig[1].cam_from_world.Inverse(), in_camera), 1e-12));
}

TEST(Ho3dFrameSource, SplitFolderListsCalibratedSequences) {
  const Ho3dFixture fx = WriteHo3dFixture(testing::ScratchDir(), 2);
  // A single-camera sequence without multi-camera calibration is not part of it.
  WriteJpeg(fx.split + "/MC1/rgb/0000.jpg", fx.frames[0].views[0].rgb);
  const Ho3dFrameSource source(fx.split);
  EXPECT_EQ(source.FrameIds(), (std::vector<std::string>{"ABF1/0000", "ABF1/0001"}));
  const FrameInput frame = source.Load("ABF1/0001");
  EXPECT_EQ(frame.image_paths[2], fx.split + "/" + fx.rig[2].name + "/rgb/0001.jpg");
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load("0001"); }), HasSubstr("frame id"));
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load("ABF1/0002"); }),
              HasSubstr("frame id"));
}

TEST(Ho3dFrameSource, BrokenLayoutsNameTheFileAndField) {
  const Ho3dFixture fx = WriteHo3dFixture(testing::ScratchDir(), 2);
  // An image missing in one camera fails that frame only.
  fs::remove(fx.split + "/ABF12/rgb/0001.jpg");
  const Ho3dFrameSource source(fx.split + "/ABF1");
  EXPECT_EQ(source.FrameIds().size(), 2u);
  EXPECT_NO_THROW(source.Load("0000"));
  std::string error = testing::InputErrorOf([&] { source.Load("0001"); });
  EXPECT_THAT(error, HasSubstr(fx.split + "/ABF12/rgb/0001.jpg"));
  EXPECT_THAT(error, HasSubstr("ABF12"));
  // A broken meta pickle fails its frame, naming it.
  std::ofstream(fx.split + "/" + fx.rig[0].name + "/meta/0000.pkl") << "garbage";
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load("0000"); }),
              HasSubstr(fx.rig[0].name + "/meta/0000.pkl"));
  // A camera folder listed by the calibration is missing.
  fs::rename(fx.split + "/ABF11", fx.split + "/moved");
  error = testing::InputErrorOf([&] { Ho3dFrameSource{fx.split + "/ABF1"}; });
  EXPECT_THAT(error, HasSubstr("ABF11/rgb"));
  EXPECT_THAT(error, HasSubstr("cam_orders.txt"));
  fs::rename(fx.split + "/moved", fx.split + "/ABF11");
  // A calibration file is broken.
  std::ofstream(fx.root + "/calibration/ABF1/calibration/cam_1_intrinsics.txt")
      << "fx:600, fy:600\n";
  error = testing::InputErrorOf([&] { Ho3dFrameSource{fx.split + "/ABF1"}; });
  EXPECT_THAT(error, HasSubstr("cam_1_intrinsics.txt"));
  EXPECT_THAT(error, HasSubstr("ppx"));
  // Not an HO3D sequence.
  EXPECT_THAT(testing::InputErrorOf([&] { Ho3dFrameSource{fx.split + "/XYZ1"}; }),
              HasSubstr("input.path"));
  EXPECT_THAT(testing::InputErrorOf([&] { Ho3dFrameSource{fx.root + "/nowhere/ABF1"}; }),
              HasSubstr("input.path"));
}

}  // namespace
}  // namespace handlabel
