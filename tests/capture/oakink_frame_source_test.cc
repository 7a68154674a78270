// The OakInk-Image frame source against a fixture written in OakInk's layout from a
// synthetic capture (general_info, hand_j and hand_v pickles, PNG streams), and against
// the numpy-written calibration fixture of tests/data/calib.
#include "capture/oakink_frame_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "capture/synth_capture.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "image/image.h"
#include "image/image_file.h"
#include "tests/capture/oakink_fixture.h"
#include "tests/hand/mano_sized_model.h"  // Py2PickleWriter
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using namespace testing;  // the fixture

TEST(OakInkFrameSource, LoadsTheRigImagesAndTruthThatWereWritten) {
  const OakInkFixture fx = WriteOakInkFixture(testing::ScratchDir());
  const OakInkFrameSource source(fx.image_dir);
  EXPECT_EQ(source.FrameIds(), fx.ids);
  EXPECT_EQ(source.side(), HandSide::kRight);
  for (size_t f = 0; f < fx.ids.size(); ++f) {
    const FrameInput frame = source.Load(fx.ids[f]);
    ASSERT_EQ(frame.rig.size(), 4u);
    EXPECT_TRUE(frame.keypoints_2d.empty());
    for (size_t v = 0; v < 4; ++v) {
      EXPECT_EQ(frame.rig[v].name, fx.rig[v].name);
      EXPECT_EQ(frame.rig[v].camera.width(), 848);
      for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(frame.rig[v].camera.params()[i], fx.rig[v].camera.params()[i], 1e-12);
      EXPECT_THAT(frame.rig[v].cam_from_world,
                  testing::Rigid3Near(fx.rig[v].cam_from_world, 1e-12, 1e-12));
      EXPECT_THAT(frame.image_paths[v], HasSubstr("/" + OakInkStreamName(fx.rig[v].name) +
                                                  "_" + std::to_string(12 + f) + ".png"));
      // PNG: pixel for pixel the rendered view.
      EXPECT_EQ(ReadImageFile(frame.image_paths[v]).data, fx.frames[f].views[v].rgb.data);
    }
    ASSERT_TRUE(frame.ground_truth.has_value());
    EXPECT_THAT(frame.ground_truth->keypoints,
                testing::MatrixNear(fx.frames[f].scene.hand.keypoints, 1e-6));
    EXPECT_THAT(frame.ground_truth->vertices,
                testing::MatrixNear(fx.frames[f].scene.hand.vertices, 1e-6));
  }
  EXPECT_EQ(OakInkStreamName("2"), "north_west_color");
  // The OakInk root (holding image/) works as well.
  EXPECT_EQ(OakInkFrameSource(fs::path(fx.image_dir).parent_path().string()).FrameIds(),
            fx.ids);
}

TEST(OakInkFrameSource, CamerasOfTheNumpyWrittenCalibrationFixture) {
  const std::string root = testing::ScratchDir();
  const std::string data = std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/calib";
  fs::create_directories(root + "/image/anno");
  fs::copy(data + "/oakink/image/anno/general_info", root + "/image/anno/general_info");
  const OakInkFrameSource source(root);
  const std::string group = "A01001_0001_0000__2021-09-26-19-59-58__0__00012";
  ASSERT_EQ(source.FrameIds().size(), 2u);
  EXPECT_EQ(source.FrameIds()[0], group);
  // Images named after the <cam> text when it is not an index.
  const std::string streams = root +
                              "/image/stream_release_v2/A01001_0001_0000/"
                              "2021-09-26-19-59-58/";
  for (const char* cam : {"north_east", "north_west", "south_east", "south_west"})
    WritePng(streams + cam + "_00012.png", ImageU8(8, 8, 3));
  const FrameInput frame = source.Load(group);
  std::ifstream in(data + "/truth.json");
  const nlohmann::json truth = nlohmann::json::parse(in)["oakink"];
  ASSERT_EQ(frame.rig.size(), truth.size());
  for (size_t v = 0; v < truth.size(); ++v) {
    EXPECT_EQ(frame.rig[v].name, truth[v]["name"].get<std::string>());
    const std::vector<double> params = truth[v]["params"];
    for (int i = 0; i < 4; ++i)
      EXPECT_NEAR(frame.rig[v].camera.params()[i], params[i], 1e-3);
    const std::vector<double> m = truth[v]["cam_from_world"];
    EXPECT_THAT(frame.rig[v].cam_from_world.ToMatrix(),
                testing::MatrixNear(
                    Eigen::Matrix<double, 3, 4, Eigen::RowMajor>(m.data()), 1e-5));
  }
  EXPECT_FALSE(frame.ground_truth.has_value());  // no hand_j folder
}

TEST(OakInkFrameSource, BrokenLayoutsNameTheFileAndField) {
  const OakInkFixture fx = WriteOakInkFixture(testing::ScratchDir(), 2);
  const std::string anno = fx.image_dir + "/anno";
  // A missing image fails its frame only.
  const std::string image = fx.image_dir +
                            "/stream_release_v2/A01001_0001_0000/2021-09-26-19-59-58/"
                            "south_west_color_13.png";
  fs::remove(image);
  const OakInkFrameSource source(fx.image_dir);
  EXPECT_NO_THROW(source.Load(fx.ids[0]));
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load(fx.ids[1]); }), HasSubstr(image));
  // A hand_j file of the wrong shape.
  WritePickle(anno + "/hand_j/" + fx.ids[0] + "__0.pkl",
              PointsPickle(fx.frames[0].scene.hand.keypoints.topRows(5), Rigid3()));
  std::string error = testing::InputErrorOf([&] { source.Load(fx.ids[0]); });
  EXPECT_THAT(error, HasSubstr("hand_j/" + fx.ids[0] + "__0.pkl"));
  EXPECT_THAT(error, HasSubstr("21 x 3"));
  EXPECT_THAT(testing::InputErrorOf([&] { source.Load("nope"); }), HasSubstr("frame id"));
  // A misnamed pickle and a missing folder stop the job before it starts.
  std::ofstream(anno + "/general_info/stray.pkl") << "x";
  error = testing::InputErrorOf([&] { OakInkFrameSource{fx.image_dir}; });
  EXPECT_THAT(error, HasSubstr("stray.pkl"));
  EXPECT_THAT(error, HasSubstr("<seq>__<ts>__<sbj>__<frame>__<cam>.pkl"));
  EXPECT_THAT(testing::InputErrorOf([&] { OakInkFrameSource{anno}; }),
              HasSubstr("input.path"));
}

}  // namespace
}  // namespace handlabel
