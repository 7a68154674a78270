#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cameras/rig_json.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::RunHandlabelCommand;
using testing::ScratchDir;

Rig SmallRig() {
  Rig rig;
  for (int i = 0; i < 4; ++i) {
    const double a = 0.4 * i;
    const Eigen::Vector3d eye(std::sin(a), -0.3, -std::cos(a));
    rig.Add({"cam" + std::to_string(i),
             Camera(CameraModelId::kOpenCV, 640, 480,
                    {500.0 + i, 501.0 + i, 320, 240, 0.01 * i, -0.002, 0.001, 0}),
             LookAt(eye, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -1, 0))});
  }
  return rig;
}

// Width and height from a PNG's IHDR chunk (bytes 16-23, big-endian).
std::pair<int, int> PngSize(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[24] = {};
  in.read(reinterpret_cast<char*>(header), 24);
  if (std::string(reinterpret_cast<char*>(header) + 1, 3) != "PNG") return {0, 0};
  const auto be = [&](int o) {
    return (header[o] << 24) | (header[o + 1] << 16) | (header[o + 2] << 8) |
           header[o + 3];
  };
  return {be(16), be(20)};
}

TEST(CamerasCommand, ConvertsJsonToColmapAndBack) {
  const std::string dir = ScratchDir();
  const Rig rig = SmallRig();
  WriteRigJson(rig, dir + "/rig.json");
  auto r =
      RunHandlabelCommand({"cameras", "convert", "--from", "json:" + dir + "/rig.json",
                           "--to", "colmap-text:" + dir + "/sparse"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/sparse/images.txt"));
  r = RunHandlabelCommand({"cameras", "convert", "--from", "colmap:" + dir + "/sparse",
                           "--to", "json:" + dir + "/out/back.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Rig back = ReadRigJson(dir + "/out/back.json");
  ASSERT_EQ(back.size(), rig.size());
  for (size_t i = 0; i < rig.size(); ++i) {
    EXPECT_EQ(back[i].name, rig[i].name);
    EXPECT_EQ(back[i].camera.params(), rig[i].camera.params());
    EXPECT_THAT(back[i].cam_from_world,
                testing::Rigid3Near(rig[i].cam_from_world, 1e-14, 0));
  }
}

TEST(CamerasCommand, ShowPrintsATableAndDrawsThePlot) {
  const std::string dir = ScratchDir();
  WriteRigJson(SmallRig(), dir + "/rig.json");
  const auto r = RunHandlabelCommand(
      {"cameras", "show", "json:" + dir + "/rig.json", "--plot", dir + "/rig.png"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* needle : {"cam0", "cam3", "OPENCV", "640x480", "503.0"}) {
    EXPECT_NE(r.out.find(needle), std::string::npos) << needle << " in\n" << r.out;
  }
  EXPECT_EQ(PngSize(dir + "/rig.png"), std::make_pair(1200, 630));
}

TEST(CamerasCommand, BadSpecsAreReportedClearly) {
  const std::string dir = ScratchDir();
  auto r = RunHandlabelCommand({"cameras", "show", "nonsense:" + dir});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("'nonsense'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("colmap"), std::string::npos) << r.err;
  r = RunHandlabelCommand({"cameras", "show", "rig.json"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("FORMAT:PATH"), std::string::npos) << r.err;
  r = RunHandlabelCommand({"cameras", "show", "colmap:" + dir});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("cameras.bin"), std::string::npos) << r.err;
  r = RunHandlabelCommand({"cameras", "frobnicate"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(RunHandlabelCommand({"cameras", "convert", "--help"}).status, 0);
}

}  // namespace
}  // namespace handlabel
