// The DexYCB frame source against a fixture written in the DexYCB layout from a
// synthetic capture (tests/capture/dexycb_fixture.h): the rig, images, 2D keypoints
// and ground truth it loads are the ones that were written.
#include "capture/dexycb_frame_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "image/image_file.h"
#include "tests/capture/dexycb_fixture.h"
#include "tests/image_difference.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::DexYcbFixture;
using testing::DexYcbFixtureOptions;
using ::testing::HasSubstr;
using testing::WriteDexYcbFixture;

using testing::ImageDifference;

TEST(DexYcbFrameSource, LoadsTheRigImagesKeypointsAndTruthThatWereWritten) {
  const DexYcbFixture fx =
      WriteDexYcbFixture(testing::ScratchDir(), MakeCapsuleHand(HandSide::kRight));
  const DexYcbFrameSource source(fx.sequence);
  EXPECT_EQ(source.FrameIds(), (std::vector<std::string>{"000000", "000001", "000002"}));
  EXPECT_EQ(source.side(), HandSide::kRight);
  EXPECT_THAT(source.Describe(), HasSubstr("4 cameras, 3 frames"));
  int worst_level = 0;
  for (int f = 0; f < 3; ++f) {
    const FrameInput frame = source.Load(testing::DexYcbNumber(f));
    ASSERT_EQ(frame.rig.size(), fx.rig.size());
    ASSERT_EQ(frame.image_paths.size(), fx.rig.size());
    ASSERT_EQ(frame.keypoints_2d.size(), fx.rig.size());
    EXPECT_TRUE(frame.mask_paths.empty());
    for (size_t v = 0; v < fx.rig.size(); ++v) {
      const RigCamera& got = frame.rig[v];
      const RigCamera& want = fx.rig[v];
      EXPECT_EQ(got.name, want.name);
      EXPECT_EQ(got.camera.model(), CameraModelId::kPinhole);
      EXPECT_EQ(got.camera.width(), 160);
      EXPECT_EQ(got.camera.height(), 120);
      for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(got.camera.params()[i], want.camera.params()[i], 1e-12);
      EXPECT_THAT(got.cam_from_world,
                  testing::Rigid3Near(want.cam_from_world, 1e-12, 1e-12));
      // The image is this camera's render of this frame: JPEG at quality 100 with
      // full chroma is within a few levels everywhere, and pixel-for-pixel what the
      // file decodes to; another camera's render is far off.
      EXPECT_EQ(frame.image_paths[v], fx.sequence + "/" + want.name + "/color_" +
                                          testing::DexYcbNumber(f) + ".jpg");
      const ImageU8 image = ReadImageFile(frame.image_paths[v]);
      const auto [mean, worst] = ImageDifference(image, fx.frames[f].views[v].rgb);
      EXPECT_LT(mean, 1.0);
      EXPECT_LE(worst, 6);
      worst_level = std::max(worst_level, worst);
      EXPECT_EQ(ImageDifference(image, ReadJpeg(frame.image_paths[v])).second, 0);
      const size_t other = (v + 1) % fx.rig.size();
      EXPECT_GT(ImageDifference(image, fx.frames[f].views[other].rgb).first, 5.0);
      ASSERT_TRUE(frame.keypoints_2d[v].has_value());
      EXPECT_THAT(frame.keypoints_2d[v]->uv_px,
                  testing::MatrixNear(fx.frames[f].views[v].keypoints, 1e-9));
      EXPECT_EQ(frame.keypoints_2d[v]->confidence.minCoeff(), 1.0);
    }
    ASSERT_TRUE(frame.ground_truth.has_value());
    EXPECT_THAT(frame.ground_truth->keypoints,
                testing::MatrixNear(fx.frames[f].scene.hand.keypoints, 1e-9));
    EXPECT_EQ(frame.ground_truth->vertices.rows(), 0);
    EXPECT_FALSE(frame.ground_truth->params.has_value());
  }
  RecordProperty("worst_jpeg_level", worst_level);
}

TEST(DexYcbFrameSource, WithoutLabelsFilesThereIsNoEvidenceOrTruth) {
  DexYcbFixtureOptions o;
  o.labels = false;
  o.num_frames = 1;
  o.side = "left";
  const DexYcbFixture fx =
      WriteDexYcbFixture(testing::ScratchDir(), MakeCapsuleHand(HandSide::kLeft), o);
  const DexYcbFrameSource source(fx.sequence);
  EXPECT_EQ(source.side(), HandSide::kLeft);
  const FrameInput frame = source.Load("000000");
  EXPECT_EQ(frame.image_paths.size(), 4u);
  EXPECT_TRUE(frame.keypoints_2d.empty());
  EXPECT_FALSE(frame.ground_truth.has_value());
}

TEST(DexYcbFrameSource, ViewsWithoutTheHandHaveNoKeypoints) {
  DexYcbFixtureOptions o;
  o.num_frames = 1;
  const DexYcbFixture fx =
      WriteDexYcbFixture(testing::ScratchDir(), MakeCapsuleHand(HandSide::kRight), o);
  // DexYCB writes -1 everywhere when the hand is not annotated.
  const Eigen::MatrixXd minus_one = Eigen::MatrixXd::Constant(21, 3, -1.0);
  NdArray joint_2d = NdArray::FromMatrix(minus_one.leftCols(2));
  joint_2d.shape = {1, 21, 2};
  NdArray joint_3d = NdArray::FromMatrix(minus_one);
  joint_3d.shape = {1, 21, 3};
  WriteNpzFile(fx.sequence + "/" + fx.rig[0].name + "/labels_000000.npz",
               {{"joint_2d", joint_2d}, {"joint_3d", joint_3d}});
  const FrameInput frame = DexYcbFrameSource(fx.sequence).Load("000000");
  EXPECT_FALSE(frame.keypoints_2d[0].has_value());
  EXPECT_TRUE(frame.keypoints_2d[1].has_value());
  // The truth then comes from the next view, in the same world frame.
  ASSERT_TRUE(frame.ground_truth.has_value());
  EXPECT_THAT(frame.ground_truth->keypoints,
              testing::MatrixNear(fx.frames[0].scene.hand.keypoints, 1e-9));
}

TEST(DexYcbFrameSource, SeveralSequencesGetSubjectAndSequenceInTheirIds) {
  const std::string root = testing::ScratchDir();
  DexYcbFixtureOptions a, b;
  a.num_frames = 2;
  b.num_frames = 1;
  b.sequence = "20200709_142123";
  b.seed = 9;
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  WriteDexYcbFixture(root, model, a);
  const DexYcbFixture fb = WriteDexYcbFixture(root, model, b);
  const std::string s = "20200709-subject-01/";
  const std::vector<std::string> want = {s + "20200709_141754/000000",
                                         s + "20200709_141754/000001",
                                         s + "20200709_142123/000000"};
  // From the root and from the subject folder.
  EXPECT_EQ(DexYcbFrameSource(root).FrameIds(), want);
  const DexYcbFrameSource source(root + "/20200709-subject-01");
  EXPECT_EQ(source.FrameIds(), want);
  const FrameInput frame = source.Load(want[2]);
  EXPECT_EQ(frame.image_paths[1],
            fb.sequence + "/" + fb.rig[1].name + "/color_000000.jpg");
  EXPECT_THAT(frame.ground_truth->keypoints,
              testing::MatrixNear(fb.frames[0].scene.hand.keypoints, 1e-9));
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load(s + "20200709_142123/000001"); }),
              HasSubstr("frame id"));
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load("000000"); }),
              HasSubstr("frame id"));

  // One job fits one hand model: mixed sides are refused, naming the sequence.
  DexYcbFixtureOptions c = b;
  c.sequence = "20200709_150000";
  c.side = "left";
  WriteDexYcbFixture(root, MakeCapsuleHand(HandSide::kLeft), c);
  const std::string error = testing::InputErrorOf([&] { DexYcbFrameSource{root}; });
  EXPECT_THAT(error, HasSubstr("20200709_150000/meta.yml"));
  EXPECT_THAT(error, HasSubstr("mano_sides"));
}

TEST(DexYcbFrameSource, CamerasFileReplacesTheCalibrationBySerial) {
  DexYcbFixtureOptions o;
  o.num_frames = 1;
  const DexYcbFixture fx =
      WriteDexYcbFixture(testing::ScratchDir(), MakeCapsuleHand(HandSide::kRight), o);
  Rig other;  // reversed order, moved cameras
  for (size_t i = fx.rig.size(); i-- > 0;) {
    RigCamera camera = fx.rig[i];
    camera.cam_from_world.translation.x() += 0.01 * static_cast<double>(i + 1);
    other.Add(camera);
  }
  const FrameInput frame = DexYcbFrameSource(fx.sequence, other).Load("000000");
  for (size_t v = 0; v < fx.rig.size(); ++v) {
    EXPECT_EQ(frame.rig[v].name, fx.rig[v].name);
    EXPECT_THAT(frame.rig[v].cam_from_world,
                testing::Rigid3Near(other.Find(fx.rig[v].name).cam_from_world, 0, 0));
  }
}

TEST(DexYcbFrameSource, BrokenLayoutsNameTheFileAndField) {
  DexYcbFixtureOptions o;
  o.num_frames = 2;
  const DexYcbFixture fx =
      WriteDexYcbFixture(testing::ScratchDir(), MakeCapsuleHand(HandSide::kRight), o);
  const std::string meta = fx.sequence + "/meta.yml";

  // A frame's image is missing: that frame fails, naming the file; the others load.
  const std::string image = fx.sequence + "/" + fx.rig[2].name + "/color_000001.jpg";
  fs::remove(image);
  const DexYcbFrameSource source(fx.sequence);
  EXPECT_NO_THROW(source.Load("000000"));
  std::string error = testing::InputErrorOf([&] { source.Load("000001"); });
  EXPECT_THAT(error, HasSubstr(image));
  EXPECT_THAT(error, HasSubstr(fx.rig[2].name));
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load("000002"); }),
              HasSubstr("000000..000001"));

  // A labels file without joint_2d.
  WriteNpzFile(fx.sequence + "/" + fx.rig[1].name + "/labels_000000.npz",
               {{"seg", NdArray::FromMatrix(Eigen::MatrixXd::Zero(2, 2))}});
  error = testing::InputErrorOf([&] { source.Load("000000"); });
  EXPECT_THAT(error, HasSubstr("labels_000000.npz"));
  EXPECT_THAT(error, HasSubstr("joint_2d"));

  // A camera folder is missing.
  fs::rename(fx.sequence + "/" + fx.rig[3].name, fx.sequence + "/moved");
  error = testing::InputErrorOf([&] { DexYcbFrameSource{fx.sequence}; });
  EXPECT_THAT(error, HasSubstr(meta));
  EXPECT_THAT(error, HasSubstr("serials"));
  EXPECT_THAT(error, HasSubstr(fx.rig[3].name));
  fs::rename(fx.sequence + "/moved", fx.sequence + "/" + fx.rig[3].name);

  // meta.yml fields.
  const auto with_meta = [&](const std::string& text) {
    std::ofstream(meta) << text;
    return testing::InputErrorOf([&] { DexYcbFrameSource{fx.sequence}; });
  };
  const std::string serials = "serials: ['" + fx.rig[0].name + "']\n";
  const std::string calib = "extrinsics: 20200709-subject-01\n";
  error = with_meta(serials + calib + "num_frames: many\nmano_sides: [right]\n");
  EXPECT_THAT(error, HasSubstr(meta));
  EXPECT_THAT(error, HasSubstr("num_frames"));
  EXPECT_THAT(error, HasSubstr("'many'"));
  EXPECT_THAT(with_meta(serials + calib + "num_frames: 2\n"), HasSubstr("mano_sides"));
  EXPECT_THAT(with_meta(serials + calib + "num_frames: 2\nmano_sides: [both]\n"),
              HasSubstr("'both'"));
  EXPECT_THAT(with_meta(calib + "num_frames: 2\nmano_sides: [right]\n"),
              HasSubstr("serials"));
  EXPECT_THAT(with_meta(serials + "num_frames: 2\nmano_sides: [right]\n"),
              HasSubstr("extrinsics"));
  EXPECT_THAT(with_meta("serials: [a\n"), HasSubstr("YAML"));
  EXPECT_THAT(testing::InputErrorOf([&] { DexYcbFrameSource{fx.root + "/calibration"}; }),
              HasSubstr("meta.yml"));
}

}  // namespace
}  // namespace handlabel
