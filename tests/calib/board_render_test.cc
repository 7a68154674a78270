#include "calib/board_render.h"

#include <gtest/gtest.h>

#include "calib/board_detect.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::Uniform;

// A board about 0.6 m in front of the camera, tilted by up to ~35 degrees.
Rigid3 FrontalPose(const BoardSpec& board) {
  const Eigen::Vector3d centre(Uniform(-0.05, 0.05), Uniform(-0.05, 0.05),
                               Uniform(0.5, 0.7));
  // OpenCV's board frame: x right, y down the printed board, z into the board, so
  // the camera looking at the printed side sees the board axes like its own.
  const Eigen::Matrix3d facing = Eigen::Matrix3d::Identity();
  const Eigen::Quaterniond tilt(
      Eigen::AngleAxisd(Uniform(-0.6, 0.6), Eigen::Vector3d::UnitX()) *
      Eigen::AngleAxisd(Uniform(-0.6, 0.6), Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(Uniform(-0.3, 0.3), Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond rotation = tilt * Eigen::Quaterniond(facing);
  const Eigen::Vector3d board_centre(board.Width() / 2, board.Height() / 2, 0);
  return Rigid3(rotation, centre - rotation * board_centre);
}

// Largest distance between detected corners and the true projections.
double DetectionError(const BoardSpec& board, const Camera& camera, int poses,
                      int* found) {
  BoardRenderer renderer(board, camera);
  double worst = 0;
  *found = 0;
  for (int p = 0; p < poses; ++p) {
    const Rigid3 pose = FrontalPose(board);
    const BoardObservation obs = DetectBoard(renderer.Render(pose, p), board);
    for (size_t i = 0; i < obs.size(); ++i) {
      Eigen::Vector2d truth;
      EXPECT_TRUE(camera.Project(pose * board.Corner(obs.ids[i]), &truth));
      worst = std::max(worst, (truth - obs.pixels[i]).norm());
    }
    *found += static_cast<int>(obs.size());
  }
  return worst;
}

const Camera kCamera(CameraModelId::kOpenCV, 640, 480,
                     {615, 612, 318, 243, 0.08, -0.12, 0.001, -0.0005});

TEST(BoardRender, DetectedCharucoCornersLandOnTheTrueProjections) {
  for (const char* spec :
       {"charuco:7x5:0.04:0.03", "charuco:6x4:0.05:0.035:DICT_5X5_50"}) {
    const BoardSpec board = ParseBoardSpec(spec);
    int found = 0;
    const double worst = DetectionError(board, kCamera, 4, &found);
    EXPECT_GT(found, 4 * board.NumCorners() * 3 / 4) << spec;
    EXPECT_LT(worst, 0.25) << spec;
    std::cout << spec << ": " << found << " corners, worst error " << worst << " px\n";
  }
}

TEST(BoardRender, DetectedCheckerboardCornersLandOnTheTrueProjections) {
  const BoardSpec board = ParseBoardSpec("checkerboard:8x6:0.03");
  int found = 0;
  const double worst = DetectionError(board, kCamera, 4, &found);
  EXPECT_EQ(found, 4 * board.NumCorners());
  EXPECT_LT(worst, 0.25);
  std::cout << "checkerboard: worst error " << worst << " px\n";
}

TEST(BoardRender, BoardOutOfViewGivesNoDetection) {
  const BoardSpec board = ParseBoardSpec("charuco:7x5:0.04:0.03");
  BoardRenderer renderer(board, kCamera);
  const Rigid3 away(Eigen::Quaterniond::Identity(), Eigen::Vector3d(5, 0, 1));
  EXPECT_EQ(DetectBoard(renderer.Render(away, 1), board).size(), 0u);
}

TEST(BoardSpec, ParsesAndRejectsSpecs) {
  const BoardSpec b = ParseBoardSpec("charuco:7x5:0.04:0.03:DICT_6X6_250");
  EXPECT_EQ(b.cols, 7);
  EXPECT_EQ(b.NumCorners(), 24);
  EXPECT_EQ(b.Corner(7), Eigen::Vector3d(0.08, 0.08, 0));
  EXPECT_EQ(ParseBoardSpec(b.ToString()).ToString(), b.ToString());
  for (const char* bad :
       {"charuco:7x5:0.04", "charuco:7x5:0.04:0.05", "charuco:7:0.04:0.03",
        "charuco:7x5:-1:0.03", "checkerboard:1x5:0.02", "charuco:7x5:0.04:0.03:DICT_9X9",
        "charuco:20x20:0.04:0.03", "aruco:7x5:0.04"}) {
    EXPECT_THROW(ParseBoardSpec(bad), InputError) << bad;
  }
}

}  // namespace
}  // namespace handlabel
