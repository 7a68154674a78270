#include "image/image.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::ScratchDir;
using testing::TestRng;

TEST(Image, PngRoundTripEveryChannelCount) {
  for (int channels : {1, 3, 4}) {
    ImageU8 image(37, 21, channels);
    for (uint8_t& v : image.data) v = static_cast<uint8_t>(TestRng()() & 255);
    const std::string path = ScratchDir() + "/img" + std::to_string(channels) + ".png";
    WritePng(path, image);
    const ImageU8 back = ReadPng(path);
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 21);
    EXPECT_EQ(back.channels, channels);
    EXPECT_EQ(back.data, image.data);
  }
}

TEST(Image, Png16RoundTrip) {
  ImageU16 image(19, 33, 1);
  for (uint16_t& v : image.data) v = static_cast<uint16_t>(TestRng()() & 0xffff);
  const std::string path = ScratchDir() + "/depth.png";
  WritePng16(path, image);
  EXPECT_EQ(ReadPng16(path).data, image.data);
  EXPECT_THROW(ReadPng(path), InputError);  // 16-bit is not an 8-bit image
}

TEST(Image, EncodingIsDeterministic) {
  ImageU8 image(64, 48, 3);
  for (uint8_t& v : image.data) v = static_cast<uint8_t>(TestRng()() & 255);
  EXPECT_EQ(EncodePng(image), EncodePng(image));
}

TEST(Image, BadFilesNameThePath) {
  const std::string dir = ScratchDir();
  try {
    ReadPng(dir + "/missing.png");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos);
  }
  { std::ofstream(dir + "/text.png") << "not a png at all"; }
  EXPECT_THROW(ReadPng(dir + "/text.png"), InputError);
  // Truncated PNG.
  ImageU8 image(40, 40, 3, 7);
  const std::string bytes = EncodePng(image);
  {
    std::ofstream(dir + "/cut.png", std::ios::binary)
        << bytes.substr(0, bytes.size() / 2);
  }
  EXPECT_THROW(ReadPng(dir + "/cut.png"), InputError);
}

}  // namespace
}  // namespace handlabel
