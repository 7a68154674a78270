// Messages of two bad inputs that used to name no file (docs/reliability.md): a mask
// of another size than its camera, and `cameras compare` of rigs with different
// cameras. Both run through the command as a user would.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "image/image.h"
#include "pipeline/label_outputs.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

// The fitter saw only "masks[3]" and no file: the frame's reason now names the mask
// file, its camera and both sizes, and the other frame is still labelled.
TEST(BadInputMessages, MaskOfAnotherSizeFailsTheFrameNamingFileAndCamera) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 2, 11);  // 160x120, with mask files
  const std::string mask = dir + "/capture/masks/cam03/000001.png";
  ASSERT_TRUE(std::filesystem::exists(mask));
  WritePng(mask, ImageU8(80, 60, 1, 255));
  const auto r = RunHandlabelCommand({"fit", "--capture", dir + "/capture", "--out",
                                      dir + "/fit", "--masks", "truth", "--hand-model",
                                      "capsule", "--silhouette-rounds", "1"});
  EXPECT_EQ(r.status, 0) << r.err;  // failures are per frame
  const auto manifest =
      nlohmann::json::parse(testing::ReadFileBytes(ManifestPath(dir + "/fit")));
  std::map<std::string, nlohmann::json> entries;
  for (const auto& e : manifest["frames"]) entries[e["frame"]] = e;
  EXPECT_EQ(entries["000000"]["status"], "ok");
  ASSERT_EQ(entries["000001"]["status"], "failed");
  const std::string reason = entries["000001"]["reason"];
  EXPECT_THAT(reason, HasSubstr(mask));
  EXPECT_THAT(reason, HasSubstr("image size"));
  EXPECT_THAT(reason, HasSubstr("160x120 (camera cam03)"));
  EXPECT_THAT(reason, HasSubstr("got 80x60"));
}

// Was "rig compare: field 'camera'": now the rig file lacking the camera and the one
// that has it.
TEST(BadInputMessages, CamerasCompareNamesTheRigFileThatLacksACamera) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 1, 12);
  const std::string a = dir + "/capture/rig.json", b = dir + "/renamed.json";
  auto rig = nlohmann::json::parse(testing::ReadFileBytes(a));
  rig["cameras"][1]["name"] = "extra";
  std::ofstream(b) << rig.dump();
  auto r = RunHandlabelCommand({"cameras", "compare", "json:" + a, "json:" + b});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("json:" + a + ": field 'camera 'extra''"));
  EXPECT_THAT(r.err, HasSubstr("expected the same camera names in both rigs"));
  EXPECT_THAT(r.err, HasSubstr("got only in json:" + b));
  r = RunHandlabelCommand(
      {"cameras", "compare", "json:" + a, "json:" + b, "--camera", "extra"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("json:" + a + ": field 'reference camera'"));
  EXPECT_THAT(r.err, HasSubstr("no camera 'extra'"));
}

}  // namespace
}  // namespace handlabel
