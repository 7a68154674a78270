#include "capture/frame_images.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

RigCamera CameraOfSize(const std::string& name, int w, int h) {
  RigCamera c;
  c.name = name;
  c.camera = Camera::Pinhole(100, 100, w / 2.0, h / 2.0, w, h);
  return c;
}

// Decoded once: RGB (grey replicated), a view without a file gets 0 x 0, and the
// accessor gives the same pixels as reading the file; a misfit file is named.
TEST(FrameImages, DecodesOnceAsRgbAndReadsWhenNotDecoded) {
  const std::string dir = testing::ScratchDir();
  ImageU8 rgb(8, 6, 3), grey(8, 6, 1);
  for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = uint8_t(i * 5);
  for (size_t i = 0; i < grey.data.size(); ++i) grey.data[i] = uint8_t(i * 3);
  WritePng(dir + "/rgb.png", rgb);
  WritePng(dir + "/grey.png", grey);
  FrameInput frame;
  frame.id = "000001";
  frame.rig.Add(CameraOfSize("a", 8, 6));
  frame.rig.Add(CameraOfSize("b", 8, 6));
  frame.rig.Add(CameraOfSize("c", 8, 6));
  frame.image_paths = {dir + "/rgb.png", dir + "/grey.png", ""};
  EXPECT_EQ(FrameViewImageRgb(frame, 0).data, rgb.data);  // read: nothing decoded yet
  DecodeFrameImages(&frame);
  ASSERT_EQ(frame.images.size(), 3u);
  EXPECT_EQ(frame.images[0].data, rgb.data);
  EXPECT_EQ(frame.images[1].channels, 3);
  EXPECT_EQ(frame.images[1].at(5, 4, 2), grey.at(5, 4, 0));
  EXPECT_TRUE(frame.images[2].empty());
  frame.image_paths = {"/absent/a.png", "/absent/b.png", ""};  // decoded: no file read
  EXPECT_EQ(FrameViewImageRgb(frame, 1).data, frame.images[1].data);
  EXPECT_TRUE(FrameViewImageRgb(frame, 2).empty());

  FrameInput misfit;
  misfit.rig.Add(CameraOfSize("wide", 16, 6));
  misfit.image_paths = {dir + "/rgb.png"};
  const std::string error = testing::InputErrorOf([&] { DecodeFrameImages(&misfit); });
  EXPECT_THAT(error, HasSubstr("rgb.png"));
  EXPECT_THAT(error, HasSubstr("16x6 (camera wide)"));
  EXPECT_TRUE(misfit.images.empty());
}

}  // namespace
}  // namespace handlabel
