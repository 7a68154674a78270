// End to end: rendered board images -> detection -> calibration -> files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "calib/synthetic_board_capture.h"
#include "cameras/rig_compare.h"
#include "cameras/rig_json.h"
#include "image/image.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::RunHandlabelCommand;
using testing::ScratchDir;

TEST(CalibCommand, CalibratesRenderedBoardImages) {
  const std::string dir = ScratchDir();
  const auto r0 = RunHandlabelCommand({"calib", "render-board", "--out", dir + "/capture",
                                       "--cameras", "3", "--frames", "12",
                                       "--near-frames", "5", "--seed", "3"});
  ASSERT_EQ(r0.status, 0) << r0.err;
  const auto r =
      RunHandlabelCommand({"calib", "board", "--images", dir + "/capture/images",
                           "--board", "charuco:11x8:0.03:0.022", "--out", dir + "/out"});
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  for (const char* file : {"rig.json", "colmap/cameras.txt", "colmap/images.txt",
                           "report.json", "residuals.png", "rig.png"}) {
    EXPECT_TRUE(fs::exists(dir + "/out/" + file)) << file;
  }
  const Rig rig = ReadRigJson(dir + "/out/rig.json");
  const Rig truth = ReadRigJson(dir + "/capture/truth.json");
  const RigDifference d = CompareRigs(rig, truth);
  std::cout << RigDifferenceTable(d);
  // 3 cameras and 17 board poses, detection noise only: looser than the 8-camera
  // acceptance run, but far tighter than a broken pipeline.
  EXPECT_LT(d.worst.focal_rel, 0.01);
  EXPECT_LT(d.worst.principal_px, 3.0);
  EXPECT_LT(d.worst.rotation_deg, 0.3);
  EXPECT_LT(d.worst.centre_m, 0.005);
  std::ifstream report(dir + "/out/report.json");
  const nlohmann::json j = nlohmann::json::parse(report);
  EXPECT_LT(j["rms_px"].get<double>(), 0.3);
  EXPECT_EQ(j["cameras"].size(), 3u);
}

TEST(CalibCommand, ClearErrorsForBadCaptures) {
  const std::string dir = ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"calib", "render-board", "--out", dir + "/c",
                                 "--cameras", "2", "--frames", "3", "--near-frames", "1",
                                 "--board", "charuco:7x5:0.04:0.03"})
                .status,
            0);
  // Wrong dictionary: nothing is detected, and the message says where.
  auto r =
      RunHandlabelCommand({"calib", "board", "--images", dir + "/c/images", "--board",
                           "charuco:7x5:0.04:0.03:DICT_6X6_50", "--out", dir + "/o"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("cam0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no detections"), std::string::npos) << r.err;
  // Bad board spec.
  r = RunHandlabelCommand(
      {"calib", "board", "--images", dir + "/c/images", "--board", "charuco:7x5:0.04"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--board"), std::string::npos) << r.err;
  // Inconsistent image sizes within a camera.
  WritePng(dir + "/c/images/cam1/zzz.png", ImageU8(320, 240, 1, 128));
  r = RunHandlabelCommand({"calib", "board", "--images", dir + "/c/images", "--board",
                           "charuco:7x5:0.04:0.03"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("zzz.png"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("640x480"), std::string::npos) << r.err;
  // No camera folders.
  r = RunHandlabelCommand({"calib", "board", "--images", dir + "/c/images/cam0",
                           "--board", "charuco:7x5:0.04:0.03"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("sub-folder"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace handlabel
