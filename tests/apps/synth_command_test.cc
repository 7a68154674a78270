#include <gtest/gtest.h>

#include <filesystem>

#include "capture/capture_reader.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::RunHandlabelCommand;

TEST(SynthCommand, WritesACaptureAndAContactSheet) {
  const std::string dir = testing::ScratchDir();
  const testing::CommandResult r = RunHandlabelCommand({"synth",
                                                        "--preset",
                                                        "random",
                                                        "--cameras",
                                                        "3",
                                                        "--size",
                                                        "96x72",
                                                        "--frames",
                                                        "2",
                                                        "--seed",
                                                        "4",
                                                        "--objects",
                                                        "--depth",
                                                        "--hand-model",
                                                        "capsule",
                                                        "--threads",
                                                        "1",
                                                        "--out",
                                                        dir + "/cap",
                                                        "--contact-sheet",
                                                        dir + "/sheet.png"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote 2 frames x 3 views"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("2/2 frames"), std::string::npos) << r.err;  // progress lines
  const CaptureReader capture(dir + "/cap");
  EXPECT_EQ(capture.num_frames(), 2);
  EXPECT_EQ(capture.rig()[0].camera.width(), 96);
  EXPECT_TRUE(capture.Has(kFileDepth));
  EXPECT_EQ(capture.manifest().generator["hand_model"]["source"], "builtin:capsule");
  EXPECT_TRUE(std::filesystem::exists(dir + "/sheet.png"));
  // Running again into the same folder is refused, naming --out.
  const testing::CommandResult again =
      RunHandlabelCommand({"synth", "--frames", "1", "--size", "96x72", "--hand-model",
                           "capsule", "--out", dir + "/cap"});
  EXPECT_EQ(again.status, 1);
  EXPECT_NE(again.err.find("--out"), std::string::npos) << again.err;
}

TEST(SynthCommand, BadValuesGiveOneLineErrors) {
  const std::string dir = testing::ScratchDir();
  const testing::CommandResult size =
      RunHandlabelCommand({"synth", "--size", "640by480", "--out", dir + "/a"});
  EXPECT_EQ(size.status, 1);
  EXPECT_NE(size.err.find("--size"), std::string::npos) << size.err;
  const testing::CommandResult preset =
      RunHandlabelCommand({"synth", "--preset", "kinect", "--out", dir + "/b"});
  EXPECT_EQ(preset.status, 1);
  EXPECT_NE(preset.err.find("kinect"), std::string::npos) << preset.err;
  const testing::CommandResult model = RunHandlabelCommand(
      {"synth", "--hand-model", dir + "/missing.npz", "--out", dir + "/c"});
  EXPECT_EQ(model.status, 1);
  EXPECT_NE(model.err.find("--hand-model"), std::string::npos) << model.err;
  EXPECT_EQ(RunHandlabelCommand({"synth"}).status, 2);  // --out missing
  EXPECT_EQ(RunHandlabelCommand({"synth", "--help"}).status, 0);
}

}  // namespace
}  // namespace handlabel
