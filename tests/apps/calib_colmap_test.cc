// `handlabel calib colmap` on a synthetic textured scene, with the real colmap binary.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <random>

#include "calib/board_scale.h"
#include "calib/synthetic_board_capture.h"
#include "cameras/rig_compare.h"
#include "cameras/rig_json.h"
#include "image/image.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

// Grey level of a multi-scale random checker texture at (u, v) metres.
double Texture(double u, double v, int plane) {
  double value = 0, weight = 0;
  for (double cell : {0.08, 0.03, 0.012}) {
    const long i = static_cast<long>(std::floor(u / cell)),
               j = static_cast<long>(std::floor(v / cell));
    uint64_t h = static_cast<uint64_t>(i * 73856093L) ^
                 static_cast<uint64_t>(j * 19349663L) ^
                 static_cast<uint64_t>((plane + 1) * 83492791L) ^
                 static_cast<uint64_t>(cell * 1e6);
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    value += (h % 256) * cell;
    weight += cell;
  }
  return value / weight;
}

// A floor (z = 0) and two walls (x = -0.6, y = -0.6), textured.
ImageU8 RenderScene(const RigCamera& c) {
  ImageU8 image(c.camera.width(), c.camera.height(), 1);
  const Rigid3 world_from_cam = c.cam_from_world.Inverse();
  const Eigen::Vector3d origin = c.CenterInWorld();
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Eigen::Vector3d dir =
          world_from_cam.rotation * c.camera.Unproject(Eigen::Vector2d(x, y));
      double best = 1e9, value = 40;
      const Eigen::Vector3d normals[3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
      const double offsets[3] = {0, -0.6, -0.6};
      for (int p = 0; p < 3; ++p) {
        const double denom = normals[p].dot(dir);
        if (std::abs(denom) < 1e-9) continue;
        const double t = (offsets[p] - normals[p].dot(origin)) / denom;
        if (t <= 0 || t >= best) continue;
        const Eigen::Vector3d hit = origin + t * dir;
        if (hit.x() < -0.6 - 1e-9 || hit.y() < -0.6 - 1e-9 || hit.z() < -1e-9) continue;
        best = t;
        value = p == 0   ? Texture(hit.x(), hit.y(), 0)
                : p == 1 ? Texture(hit.y(), hit.z(), 1)
                         : Texture(hit.x(), hit.z(), 2);
      }
      image.at(x, y) = static_cast<uint8_t>(std::clamp(value, 0.0, 255.0));
    }
  }
  return image;
}

// 4 cameras on an arc looking at the scene, each with one image of it.
Rig MakeSceneRig(const std::string& dir) {
  Rig truth;
  // Small images and few cameras keep COLMAP's run short.
  for (int i = 0; i < 4; ++i) {
    const double a = 0.3 * i;
    const Eigen::Vector3d eye(0.9 * std::cos(a) + 0.2, 0.9 * std::sin(a) + 0.2, 0.7);
    truth.Add({"cam" + std::to_string(i),
               Camera::Pinhole(250, 250, 159.5, 119.5, 320, 240),
               LookAt(eye, Eigen::Vector3d(-0.1, -0.1, 0.1), Eigen::Vector3d::UnitZ())});
    fs::create_directories(dir + "/images/" + truth[i].name);
    WritePng(dir + "/images/" + truth[i].name + "/000000.png", RenderScene(truth[i]));
  }
  return truth;
}

TEST(CalibColmap, RecoversASyntheticRigUpToTheKnownScale) {
  if (std::system("colmap help > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "no colmap binary";
  const std::string dir = testing::ScratchDir();
  const Rig truth = MakeSceneRig(dir);
  const double distance = (truth[0].CenterInWorld() - truth[3].CenterInWorld()).norm();
  const auto r = testing::RunHandlabelCommand(
      {"calib", "colmap", "--images", dir + "/images", "--model", "SIMPLE_PINHOLE",
       "--scale", "cam0,cam3," + std::to_string(distance), "--out", dir + "/out",
       "--threads", "1"});
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  const RigDifference d = CompareRigs(ReadRigJson(dir + "/out/rig.json"), truth);
  std::cout << RigDifferenceTable(d);
  EXPECT_LT(d.worst.focal_rel, 0.02);
  EXPECT_LT(d.worst.rotation_deg, 0.5);
  EXPECT_LT(d.worst.centre_m, 0.01);
}

TEST(CalibColmap, TakesScaleAndWorldFromABoardSeenByTwoCameras) {
  if (std::system("colmap help > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "no colmap binary";
  const std::string dir = testing::ScratchDir();
  const Rig truth = MakeSceneRig(dir);
  // One frame of a board held up towards the cameras, rendered into every camera.
  const BoardSpec board = ParseBoardSpec("charuco:7x5:0.06:0.045");
  SyntheticBoardCapture capture;
  capture.rig = truth;
  const Eigen::Vector3d target(0.4, 0.3, 0.35);
  // Board z points away from the cameras (its printed side faces them).
  const Rigid3 facing =
      LookAt(Eigen::Vector3d(0.75, 0.75, 0.9), target, Eigen::Vector3d::UnitZ())
          .Inverse();
  const Eigen::Vector3d board_centre(board.Width() / 2, board.Height() / 2, 0);
  capture.world_from_board["000000"] =
      Rigid3(facing.rotation, target - facing.rotation * board_centre);
  RenderBoardCapture(capture, board, dir + "/board");

  const auto r = testing::RunHandlabelCommand(
      {"calib", "colmap", "--images", dir + "/images", "--model", "SIMPLE_PINHOLE",
       "--board", board.ToString(), "--board-images", dir + "/board", "--world", "board",
       "--out", dir + "/out", "--threads", "1"});
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("board scale from"), std::string::npos) << r.out;
  const Rig rig = ReadRigJson(dir + "/out/rig.json");
  Rig truth_on_board = truth;
  SetWorldToBoard(&truth_on_board, capture.world_from_board.at("000000"));
  for (size_t i = 0; i < truth.size(); ++i) {
    const RigCamera& c = rig.Find(truth[i].name);
    EXPECT_LT((c.CenterInWorld() - truth_on_board[i].CenterInWorld()).norm(), 0.01)
        << c.name;
    std::cout << c.name << " centre error "
              << (c.CenterInWorld() - truth_on_board[i].CenterInWorld()).norm() << " m\n";
  }
}

TEST(CalibColmap, ScaleAndBoardOptionsAreCheckedBeforeColmapRuns) {
  const auto both = testing::RunHandlabelCommand(
      {"calib", "colmap", "--images", "x", "--scale", "a,b,1", "--board",
       "charuco:7x5:0.04:0.03", "--board-images", "y"});
  EXPECT_EQ(both.status, 1);
  EXPECT_NE(both.err.find("one source of scale"), std::string::npos) << both.err;
  const auto world = testing::RunHandlabelCommand(
      {"calib", "colmap", "--images", "x", "--world", "board"});
  EXPECT_EQ(world.status, 1);
  EXPECT_NE(world.err.find("--world"), std::string::npos) << world.err;
}

}  // namespace
}  // namespace handlabel
