// Board image folders: every format OpenCV decodes, converted to grey as OpenCV does.
#include "calib/board_images.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "calib/board_detect.h"
#include "calib/board_render.h"
#include "image/image.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

// A 24-bit BMP (bottom-up rows padded to 4 bytes) with the grey level in all three
// channels: a format that only OpenCV reads here, not image/image_file.h.
void WriteGreyBmp(const std::string& path, const ImageU8& grey) {
  const int row = (3 * grey.width + 3) / 4 * 4;
  const uint32_t pixels = static_cast<uint32_t>(row) * grey.height;
  std::string bytes(54 + pixels, '\0');
  const auto put = [&](size_t at, uint32_t value, int n) {
    for (int i = 0; i < n; ++i) bytes[at + i] = static_cast<char>(value >> (8 * i));
  };
  bytes[0] = 'B';
  bytes[1] = 'M';
  put(2, 54 + pixels, 4);  // file size
  put(10, 54, 4);          // offset of the pixels
  put(14, 40, 4);          // BITMAPINFOHEADER
  put(18, grey.width, 4);
  put(22, grey.height, 4);
  put(26, 1, 2);   // planes
  put(28, 24, 2);  // bits per pixel
  put(34, pixels, 4);
  for (int y = 0; y < grey.height; ++y) {
    for (int x = 0; x < grey.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        bytes[54 + size_t(grey.height - 1 - y) * row + 3 * x + c] =
            static_cast<char>(grey.at(x, y));
      }
    }
  }
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(BoardImages, BmpAndPngFilesGiveTheDetectionsOfTheImageInMemory) {
  const BoardSpec board = ParseBoardSpec("charuco:7x5:0.04:0.03");
  const Camera camera = Camera::Pinhole(600, 600, 319.5, 239.5, 640, 480);
  // The board centred 0.6 m in front of the camera, printed side towards it.
  const Rigid3 cam_from_board(
      Eigen::Quaterniond::Identity(),
      Eigen::Vector3d(-board.Width() / 2, -board.Height() / 2, 0.6));
  const ImageU8 image = BoardRenderer(board, camera).Render(cam_from_board, 1);
  const BoardObservation truth = DetectBoard(image, board);
  ASSERT_GT(truth.size(), static_cast<size_t>(board.NumCorners() / 2));

  const std::string dir = testing::ScratchDir();
  WritePng(dir + "/png/cam0/000000.png", image);
  fs::create_directories(dir + "/bmp/cam0");
  WriteGreyBmp(dir + "/bmp/cam0/000000.bmp", image);
  for (const char* format : {"png", "bmp"}) {
    const std::vector<CameraBoardViews> views =
        DetectBoardsInFolders(dir + "/" + format, board);
    ASSERT_EQ(views.size(), 1u) << format;
    EXPECT_EQ(views[0].width, 640) << format;
    EXPECT_EQ(views[0].height, 480) << format;
    const BoardObservation& read = views[0].frames.at("000000");
    EXPECT_EQ(read.ids, truth.ids) << format;
    EXPECT_EQ(read.pixels, truth.pixels) << format;  // the very same pixels went in
  }
}

}  // namespace
}  // namespace handlabel
