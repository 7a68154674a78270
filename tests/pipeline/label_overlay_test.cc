#include "pipeline/label_overlay.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "core/errors.h"
#include "core/image_file.h"
#include "tests/pipeline/label_test_stages.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

// A broken or wrongly sized image must fail the frame (named), not become a grey
// overlay that hides the broken capture ("0 failed").
TEST(LabelOverlay, UnreadableOrMisfitImageFailsNamingTheFile) {
  const std::string dir = testing::ScratchDir();
  const RasterOverlayWriter writer(testing::MakeStickHand(HandSide::kRight));
  FrameInput frame;
  frame.id = "000000";
  frame.rig = testing::MakeFourCameraRig();
  const std::string broken = dir + "/broken.png";
  std::ofstream(broken) << "\x89PNG not really";
  frame.image_paths = {broken, "", "", ""};
  const LabelRecord label;
  std::string error = testing::InputErrorOf([&] { writer.Write(dir, frame, label); });
  if (error == "(no InputError)") {  // a reader may throw another Error type
    try {
      writer.Write(dir, frame, label);
      error = "(nothing thrown)";
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  EXPECT_THAT(error, HasSubstr("broken.png"));
  const std::string small = dir + "/small.png";
  std::ofstream(small, std::ios::binary) << EncodePng(ImageU8(320, 240, 3, 10));
  frame.image_paths[0] = small;
  error = testing::InputErrorOf([&] { writer.Write(dir, frame, label); });
  EXPECT_THAT(error, HasSubstr("small.png"));
  EXPECT_THAT(error, HasSubstr("640x480 (camera cam0)"));
  EXPECT_THAT(error, HasSubstr("320x240"));
}

}  // namespace
}  // namespace handlabel
