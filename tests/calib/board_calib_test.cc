#include "calib/board_calib.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>

#include "calib/board_calib_init.h"
#include "calib/rig_compare.h"
#include "calib/synthetic_board_capture.h"
#include "core/errors.h"
#include "tests/pin_digest.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

const BoardSpec kBoard = ParseBoardSpec("charuco:7x5:0.04:0.03");
// More corners per view pin the principal point (and with it the rotations) down.
const BoardSpec kDenseBoard = ParseBoardSpec("charuco:11x8:0.03:0.022");

TEST(BoardCalib, DexYcbLikeRigFromNoisyCornersMeetsTheAccuracyTargets) {
  SyntheticBoardCaptureOptions options;  // 8 cameras, 640x480, 0.3 px noise
  options.seed = testing::TestSeed();
  options.num_frames = 40;
  // 32 tilted close-ups per camera pin each principal point (and with it the camera's
  // rotation) down: with 16, 2 of 6 seeds gave 0.10-0.12 deg (docs/cameras.md).
  options.near_frames_per_camera = 32;
  const SyntheticBoardCapture capture = SynthesizeBoardCapture(kDenseBoard, options);
  const BoardCalibResult result = CalibrateBoardRig(capture.views, kDenseBoard);
  const RigDifference d = CompareRigs(result.rig, capture.rig);
  std::cout << RigDifferenceTable(d) << "rms " << result.rms_px << " px\n";
  EXPECT_LT(d.worst.focal_rel, 0.005);
  EXPECT_LT(d.worst.principal_px, 2.0);
  EXPECT_LT(d.worst.rotation_deg, 0.1);
  EXPECT_LT(d.worst.centre_m, 0.002);
  EXPECT_NEAR(result.rms_px, 0.3 * std::sqrt(2.0), 0.05);  // noise-limited
  EXPECT_EQ(result.world, "camera:cam0");
  ASSERT_EQ(result.stats.size(), 8u);
  for (const CameraCalibStats& s : result.stats) EXPECT_GT(s.observations, 100) << s.name;
}

void AddRig(const Rig& rig, testing::PinDigest* d) {
  for (size_t c = 0; c < rig.size(); ++c) {
    d->Add(rig[c].name).Add(rig[c].camera.params()).Add(rig[c].cam_from_world);
  }
}

// Pins every bit of the synthetic capture, one camera's initial values and the
// calibration (with an outlier round and the board as the world) on one input.
TEST(BoardCalib, SameInputGivesTheSameBits) {
  SyntheticBoardCaptureOptions options;
  options.seed = 11;
  options.num_cameras = 3;
  options.num_frames = 12;
  options.near_frames_per_camera = 4;
  SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  testing::PinDigest in;
  AddRig(capture.rig, &in);
  in.Add(capture.world_from_board);
  for (const CameraBoardViews& v : capture.views) {
    in.Add(v.name).Add(v.width).Add(v.height);
    for (const auto& [key, obs] : v.frames) in.Add(key).Add(obs.ids).Add(obs.pixels);
  }
  EXPECT_EQ(in.Hex(), "59cdc0bef8aa1ef4");
  capture.views[1].frames.begin()->second.pixels[2] += Eigen::Vector2d(25, -12);

  const InitialCamera initial =
      InitialIntrinsics(capture.views[0], kBoard, CameraModelId::kOpenCV);
  testing::PinDigest init;
  init.Add(initial.camera.params()).Add(initial.cam_from_board).Add(initial.rms_px);
  EXPECT_EQ(init.Hex(), "76408cfc3c31f087");

  BoardCalibOptions calib;
  calib.world = "board";
  const BoardCalibResult result = CalibrateBoardRig(capture.views, kBoard, calib);
  testing::PinDigest out;
  AddRig(result.rig, &out);
  out.Add(result.world).Add(result.world_from_board).Add(result.rms_px);
  for (const CameraCalibStats& s : result.stats) {
    out.Add(s.name).Add(s.frames).Add(s.observations).Add(s.outliers);
    out.Add(s.rms_px).Add(s.initial_rms_px);
  }
  for (const CornerResidual& r : result.residuals) {
    out.Add(r.camera).Add(r.frame).Add(r.corner_id).Add(r.observed).Add(r.residual);
    out.Add(r.inlier);
  }
  for (const auto& [parent, child, weight] : result.tree) {
    out.Add(parent).Add(child).Add(weight);
  }
  int outliers = 0;
  for (const CameraCalibStats& s : result.stats) outliers += s.outliers;
  EXPECT_GE(outliers, 1);
  EXPECT_EQ(out.Hex(), "ce481e11a45f07c8");
}

TEST(BoardCalib, RejectsGrossOutliers) {
  SyntheticBoardCaptureOptions options;
  options.seed = testing::TestSeed();
  options.num_cameras = 4;
  SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  int corrupted = 0;
  for (CameraBoardViews& v : capture.views) {
    for (auto& [key, obs] : v.frames) {
      if (obs.size() > 10 && corrupted < 40) {
        obs.pixels[3] +=
            Eigen::Vector2d(testing::Uniform(8, 30), testing::Uniform(-30, 30));
        ++corrupted;
      }
    }
  }
  const BoardCalibResult result = CalibrateBoardRig(capture.views, kBoard);
  int outliers = 0;
  for (const CameraCalibStats& s : result.stats) outliers += s.outliers;
  EXPECT_GE(outliers, corrupted);
  EXPECT_LT(outliers, corrupted + 15);
  // Only 4 cameras and the small board: the outliers must not hurt, the accuracy is
  // what this data allows.
  const RigDifference d = CompareRigs(result.rig, capture.rig);
  EXPECT_LT(d.worst.rotation_deg, 0.5);
  EXPECT_LT(d.worst.centre_m, 0.005);
}

TEST(BoardCalib, WorldCanBeTheBoard) {
  SyntheticBoardCaptureOptions options;
  options.seed = testing::TestSeed();
  options.num_cameras = 3;
  options.corner_noise_px = 0;  // exact data: the frame bookkeeping must be exact too
  const SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  BoardCalibOptions calib;
  calib.world = "board";
  const BoardCalibResult result = CalibrateBoardRig(capture.views, kBoard, calib);
  const std::string key = capture.views[0].frames.begin()->first;
  EXPECT_EQ(result.world, "board:" + key);
  EXPECT_THAT(result.world_from_board.at(key),
              testing::Rigid3Near(Rigid3(), 1e-12, 1e-12));
  // Cameras relative to that board pose match the truth.
  for (size_t c = 0; c < 3; ++c) {
    const Rigid3 truth = capture.rig[c].cam_from_world * capture.world_from_board.at(key);
    EXPECT_THAT(result.rig[c].cam_from_world, testing::Rigid3Near(truth, 1e-7, 1e-7));
  }
}

TEST(BoardCalib, UnlinkedCamerasAreNamed) {
  SyntheticBoardCaptureOptions options;
  options.seed = testing::TestSeed();
  options.num_cameras = 4;
  SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  // cam2 and cam3 only see frames nobody else sees.
  for (int c = 2; c < 4; ++c) {
    std::map<std::string, BoardObservation> renamed;
    for (auto& [key, obs] : capture.views[c].frames) renamed["other_" + key] = obs;
    capture.views[c].frames = renamed;
  }
  try {
    CalibrateBoardRig(capture.views, kBoard);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("[cam2, cam3] cannot be linked to [cam0, cam1]"), std::string::npos)
        << m;
  }
}

TEST(BoardCalib, CamerasWithTooFewDetectionsAreNamed) {
  SyntheticBoardCaptureOptions options;
  options.seed = testing::TestSeed();
  options.num_cameras = 2;
  SyntheticBoardCapture capture = SynthesizeBoardCapture(kBoard, options);
  capture.views[1].frames.clear();
  try {
    CalibrateBoardRig(capture.views, kBoard);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera cam1"), std::string::npos) << e.what();
  }
  BoardCalibOptions bad;
  bad.master = "nope";
  EXPECT_THROW(CalibrateBoardRig(capture.views, kBoard, bad), InputError);
}

}  // namespace
}  // namespace handlabel
