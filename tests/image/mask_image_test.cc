#include "image/mask_image.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// The one mask rule: a pixel is hand when its value is above 127 (first channel).
TEST(MaskImage, PixelsAbove127AreHand) {
  ImageU8 image(4, 1, 1, 0);
  image.at(0, 0, 0) = 0;
  image.at(1, 0, 0) = 127;
  image.at(2, 0, 0) = 128;
  image.at(3, 0, 0) = 255;
  const std::string path = testing::ScratchDir() + "/mask.png";
  WritePng(path, image);
  const MaskImage mask = ReadMaskPng(path);
  ASSERT_EQ(mask.rows(), 1);
  ASSERT_EQ(mask.cols(), 4);
  EXPECT_EQ(mask(0, 0), 0);
  EXPECT_EQ(mask(0, 1), 0);  // an anti-aliased border pixel does not grow the mask
  EXPECT_EQ(mask(0, 2), 255);
  EXPECT_EQ(mask(0, 3), 255);
  EXPECT_EQ(MaskFromImage(image), mask);
}

TEST(MaskImage, MissingFileNamesIt) {
  const std::string path = testing::ScratchDir() + "/none.png";
  try {
    ReadMaskPng(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("none.png"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace handlabel
