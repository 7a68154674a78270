#include "pipeline/label_overlay.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "core/errors.h"
#include "image/image_file.h"
#include "pipeline/label_outputs.h"
#include "tests/image_difference.h"
#include "tests/pipeline/label_test_stages.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

// A broken or wrongly sized image must fail the frame (named), not become a grey
// overlay that hides the broken capture ("0 failed").
TEST(LabelOverlay, UnreadableOrMisfitImageFailsNamingTheFile) {
  const std::string dir = testing::ScratchDir();
  const RasterOverlayWriter writer(testing::MakeStickHand(HandSide::kRight), "png");
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

// The frame's decoded images are drawn on (no file read); JPEG and PNG overlays show
// the same picture within JPEG's loss; a view without an image is grey.
TEST(LabelOverlay, DrawsOnTheDecodedImagesInEitherFormat) {
  const std::string dir = testing::ScratchDir();
  const HandModel hand = testing::MakeStickHand(HandSide::kRight);
  FrameInput frame;
  frame.id = "000007";
  frame.rig = testing::MakeFourCameraRig();
  frame.image_paths = {dir + "/absent.png", dir + "/absent.png", "", ""};
  ImageU8 image(640, 480, 3);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = uint8_t(i / 3 % 200);
  frame.images = {image, image, ImageU8(), ImageU8()};
  const LabelRecord label;  // no mesh: the overlay is the image itself
  RasterOverlayWriter(hand, "png").Write(dir + "/png", frame, label);
  RasterOverlayWriter(hand, "jpg").Write(dir + "/jpg", frame, label);
  const ImageU8 png = ReadImageFile(OverlayPath(dir + "/png", frame.id, "cam0", "png"));
  EXPECT_EQ(png.data, image.data);
  const std::string jpg_path = OverlayPath(dir + "/jpg", frame.id, "cam0", "jpg");
  EXPECT_EQ(jpg_path.substr(jpg_path.size() - 4), ".jpg");
  const auto [mean, worst] = testing::ImageDifference(ReadImageFile(jpg_path), image);
  EXPECT_LT(mean, 2.0);
  EXPECT_EQ(testing::ReadFileBytes(jpg_path).substr(0, 3), "\xFF\xD8\xFF");  // JPEG
  const ImageU8 grey = ReadImageFile(OverlayPath(dir + "/png", frame.id, "cam2", "png"));
  EXPECT_EQ(grey.data, ImageU8(640, 480, 3, 96).data);
}

}  // namespace
}  // namespace handlabel
