// JPEG files through libjpeg, and reading PNG or JPEG by content.
#include "image/image_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "tests/image_difference.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

// Smooth gradients with a sharp-edged block in a different colour: every channel and
// both axes differ, so swapped channels, rows or a wrong stride show as large errors.
ImageU8 TestImage(int w, int h, int channels) {
  ImageU8 image(w, h, channels);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool block = x > w / 3 && x < w / 2 && y > h / 4 && y < h / 2;
      for (int c = 0; c < channels; ++c) {
        const double v = c == 0   ? 255.0 * x / w
                         : c == 1 ? 255.0 * y / h
                                  : 128 + 60 * std::sin(0.1 * (x + y));
        image.at(x, y, c) = block ? (c == 0 ? 20 : 230) : static_cast<uint8_t>(v);
      }
    }
  }
  return image;
}

using testing::ImageDifference;

std::string ErrorOf(const std::string& path) {
  try {
    ReadImageFile(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(ImageFile, JpegRoundTripKeepsSizeLayoutAndPixelsWithinQuality) {
  const std::string dir = testing::ScratchDir();
  for (int channels : {1, 3}) {
    const ImageU8 image = TestImage(37, 23, channels);  // not a multiple of 8 or 16
    JpegWriteOptions best;
    best.quality = 100;
    WriteJpeg(dir + "/sub/a.jpg", image, best);
    const ImageU8 back = ReadJpeg(dir + "/sub/a.jpg");
    ASSERT_EQ(back.width, 37);
    ASSERT_EQ(back.height, 23);
    ASSERT_EQ(back.channels, channels);
    const auto [mean, worst] = ImageDifference(back, image);
    EXPECT_LT(mean, 1.0) << channels;
    EXPECT_LE(worst, 4) << channels;
    // Lower quality is lossier, but still the same picture.
    JpegWriteOptions low;
    low.quality = 60;
    low.full_chroma = false;
    WriteJpeg(dir + "/b.jpg", image, low);
    const auto [low_mean, low_worst] = ImageDifference(ReadJpeg(dir + "/b.jpg"), image);
    EXPECT_GT(low_mean, mean);
    EXPECT_LT(low_mean, 8.0);
    EXPECT_LT(std::filesystem::file_size(dir + "/b.jpg"),
              std::filesystem::file_size(dir + "/sub/a.jpg"));
  }
}

TEST(ImageFile, EncodeJpegGivesTheBytesWriteJpegWrites) {
  const std::string dir = testing::ScratchDir();
  const ImageU8 image = TestImage(40, 30, 3);
  WriteJpeg(dir + "/a.jpg", image);
  const std::string bytes = EncodeJpeg(image);
  EXPECT_EQ(bytes, ReadFileBytes(dir + "/a.jpg", "JPEG file"));
  // The bytes are a JPEG of the image (written by hand, read back by libjpeg).
  std::ofstream(dir + "/by_hand.jpg", std::ios::binary) << bytes;
  const auto [mean, worst] = ImageDifference(ReadJpeg(dir + "/by_hand.jpg"), image);
  EXPECT_LT(mean, 2.0);
  EXPECT_LT(worst, 64);
}

TEST(ImageFile, ReadFileBytesGivesEveryByteAndNamesAMissingFile) {
  const std::string dir = testing::ScratchDir();
  std::string bytes(100000, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7 % 256);
  std::ofstream(dir + "/b.bin", std::ios::binary) << bytes;
  EXPECT_EQ(ReadFileBytes(dir + "/b.bin", "file"), bytes);
  std::ofstream(dir + "/empty.bin", std::ios::binary);
  EXPECT_EQ(ReadFileBytes(dir + "/empty.bin", "file"), "");
  std::string error = "(no InputError)";
  try {
    ReadFileBytes(dir + "/none.bin", "weights file");
  } catch (const InputError& e) {
    error = e.what();
  }
  EXPECT_THAT(error, HasSubstr(dir + "/none.bin"));
  EXPECT_THAT(error, HasSubstr("readable weights file"));
}

TEST(ImageFile, ReadsByContentNotByName) {
  const std::string dir = testing::ScratchDir();
  const ImageU8 image = TestImage(20, 10, 3);
  WritePng(dir + "/png.jpg", image);  // misnamed on purpose
  WriteJpeg(dir + "/jpeg.png", image);
  const ImageU8 png = ReadImageFile(dir + "/png.jpg");
  EXPECT_EQ(png.data, image.data);  // lossless
  EXPECT_EQ(ReadImageFile(dir + "/jpeg.png").data, ReadJpeg(dir + "/jpeg.png").data);
}

TEST(ImageFile, BadFilesNameThePath) {
  const std::string dir = testing::ScratchDir();
  EXPECT_THAT(ErrorOf(dir + "/none.jpg"), HasSubstr(dir + "/none.jpg"));
  std::ofstream(dir + "/text.jpg") << "not an image";
  EXPECT_THAT(ErrorOf(dir + "/text.jpg"), HasSubstr("PNG or JPEG"));
  EXPECT_THROW(ReadJpeg(dir + "/text.jpg"), InputError);
  // A truncated JPEG is an error, not an image with a grey bottom.
  WriteJpeg(dir + "/full.jpg", TestImage(64, 64, 3));
  std::ifstream in(dir + "/full.jpg", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(dir + "/cut.jpg", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const std::string error = ErrorOf(dir + "/cut.jpg");
  EXPECT_THAT(error, HasSubstr(dir + "/cut.jpg"));
  EXPECT_THAT(error, HasSubstr("valid JPEG"));
}

}  // namespace
}  // namespace handlabel
