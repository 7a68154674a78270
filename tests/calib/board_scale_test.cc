#include "calib/board_scale.h"

#include <gtest/gtest.h>

#include <map>

#include "calib/synthetic_board_capture.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

const BoardSpec kBoard = ParseBoardSpec("charuco:11x8:0.03:0.022");

// An SfM-like rig: the truth with the world at the first camera and an arbitrary unit.
Rig UnscaledRig(const Rig& truth, double unit) {
  Rig rig = truth;
  rig.SetWorldToCamera(0);
  ScaleRig(&rig, unit);
  return rig;
}

TEST(BoardScale, RecoversTheMetricScaleOfAnUnscaledRigFromNoisyCorners) {
  SyntheticBoardCaptureOptions options;  // 0.3 px corner noise
  options.seed = testing::TestSeed();
  options.num_frames = 10;
  options.near_frames_per_camera = 0;  // close-ups are seen by one camera: no use here
  const SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  const double unit = 0.37;
  Rig rig = UnscaledRig(capture.rig, unit);
  const BoardScaleResult r = ScaleFromBoard(rig, capture.views, kBoard, "test");
  EXPECT_NEAR(r.scale * unit, 1.0, 2e-3);
  EXPECT_GT(r.frames, 5);
  EXPECT_LT(r.spread, 0.01);

  // Applied, the rig's camera centres are where the truth's are (world at cam0).
  ScaleRig(&rig, r.scale);
  Rig truth = capture.rig;
  truth.SetWorldToCamera(0);
  for (size_t i = 0; i < rig.size(); ++i) {
    EXPECT_LT((rig[i].CenterInWorld() - truth[i].CenterInWorld()).norm(), 0.002)
        << rig[i].name;
  }
  // With the world at the board of frame r.board_frame, the centres are where the
  // truth puts them relative to that board.
  ASSERT_FALSE(r.board_frame.empty());
  SetWorldToBoard(&rig, r.world_from_board);
  Rig truth_on_board = capture.rig;
  SetWorldToBoard(&truth_on_board, capture.world_from_board.at(r.board_frame));
  for (size_t i = 0; i < rig.size(); ++i) {
    EXPECT_LT((rig[i].CenterInWorld() - truth_on_board[i].CenterInWorld()).norm(), 0.003)
        << rig[i].name;
  }
}

TEST(BoardScale, ExactCornersGiveTheExactScale) {
  SyntheticBoardCaptureOptions options;
  options.seed = testing::TestSeed();
  options.num_frames = 4;
  options.near_frames_per_camera = 0;
  options.corner_noise_px = 0;
  const SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  const BoardScaleResult r =
      ScaleFromBoard(UnscaledRig(capture.rig, 2.5), capture.views, kBoard, "test");
  EXPECT_NEAR(r.scale, 1 / 2.5, 1e-9);
}

TEST(BoardScale, NoSharedViewsIsAnErrorNamingTheCameras) {
  SyntheticBoardCaptureOptions options;
  options.seed = testing::TestSeed();
  options.num_frames = 3;
  options.near_frames_per_camera = 0;
  const SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  // The same detections, but no two cameras at the same moment (frame keys differ).
  std::vector<CameraBoardViews> views = capture.views;
  for (CameraBoardViews& v : views) {
    std::map<std::string, BoardObservation> renamed;
    for (const auto& [frame, observation] : v.frames)
      renamed[v.name + frame] = observation;
    v.frames = renamed;
  }
  try {
    ScaleFromBoard(capture.rig, views, kBoard, "board_images/");
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("board_images/"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(capture.rig[0].name), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace handlabel
