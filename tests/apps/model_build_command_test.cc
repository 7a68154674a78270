#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "hand/hand_model_io.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::RunHandlabelCommand;

// A coarse build, quick enough for a test.
std::vector<std::string> CoarseBuild(const std::string& side, const std::string& out) {
  return {"model",       "build", "--side",          side, "--out",          out,
          "--grid-step", "0.004", "--shape-samples", "40", "--pose-samples", "200"};
}

TEST(ModelBuildCommand, WritesALoadableModelAndTheSameBytesTwice) {
  const std::string dir = testing::ScratchDir();
  auto r = RunHandlabelCommand(CoarseBuild("left", dir + "/a.npz"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("closed manifold: yes"), std::string::npos) << r.out;
  r = RunHandlabelCommand(CoarseBuild("left", dir + "/b.npz"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(testing::ReadFileBytes(dir + "/a.npz"),
            testing::ReadFileBytes(dir + "/b.npz"));
  const HandModel m = LoadHandModel(dir + "/a.npz");
  EXPECT_EQ(m.side, HandSide::kLeft);
  EXPECT_EQ(m.name, "open_hand_left");
}

TEST(ModelBuildCommand, RejectsBadFlags) {
  EXPECT_EQ(RunHandlabelCommand({"model", "build", "--side", "middle", "--out", "x.npz"})
                .status,
            2);
  EXPECT_EQ(RunHandlabelCommand({"model", "build"}).status, 2);  // --out missing
  const auto r = RunHandlabelCommand(
      {"model", "build", "--out", testing::ScratchDir() + "/x.npz", "--grid-step", "0"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("grid_step"), std::string::npos) << r.err;
}

TEST(ModelRenderCommand, WritesAPngSheetOfTheShippedModel) {
  const std::string out = testing::ScratchDir() + "/sheet.png";
  const auto r = RunHandlabelCommand(
      {"model", "render",
       std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz", "--out", out,
       "--tile", "64", "--poses", "rest,fist", "--views", "palm,thumb"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string png = testing::ReadFileBytes(out);
  ASSERT_GT(png.size(), 100u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  // 2 views x 64 wide, 2 poses x 64 high.
  EXPECT_EQ(static_cast<unsigned char>(png[19]), 128);
  EXPECT_EQ(static_cast<unsigned char>(png[23]), 128);
  const auto bad = RunHandlabelCommand(
      {"model", "render",
       std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz", "--out", out,
       "--poses", "wave"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("wave"), std::string::npos);
}

}  // namespace
}  // namespace handlabel
