#include "cameras/colmap_model.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cameras/colmap_rig.h"
#include "core/errors.h"
#include "tests/cameras/rig_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::ExpectModelsEqual;
using testing::ExpectRigsEqual;
using testing::RandomColmapModel;
using testing::ScratchDir;

void WriteAll(const std::string& path, const std::string& data) {
  std::ofstream(path, std::ios::binary) << data;
}

TEST(ColmapModel, TextRoundTripIsExact) {
  const ColmapModel model = RandomColmapModel();
  const std::string dir = ScratchDir();
  WriteColmapModel(model, dir, ColmapFormat::kText);
  ExpectModelsEqual(model, ReadColmapModel(dir));
}

TEST(ColmapModel, BinaryRoundTripIsExact) {
  const ColmapModel model = RandomColmapModel();
  const std::string dir = ScratchDir();
  WriteColmapModel(model, dir, ColmapFormat::kBinary);
  ExpectModelsEqual(model, ReadColmapModel(dir));
}

TEST(ColmapModel, BinaryLayoutMatchesTheDocumentedRecordSizes) {
  ColmapModel model;
  model.cameras[1] = {1, CameraModelId::kOpenCV, 640, 480, {1, 2, 3, 4, 5, 6, 7, 8}};
  ColmapImage image;
  image.id = 4;
  image.camera_id = 1;
  image.name = "abc.png";
  image.points2D = {{1, 2}, {3, 4}};
  image.point3D_ids = {kColmapNoPoint3D, 9};
  model.images[4] = image;
  model.points3D[9] = {9, {1, 2, 3}, {1, 2, 3}, 0.5, {{4, 1}}};
  const std::string dir = ScratchDir();
  WriteColmapBinary(model, dir);
  EXPECT_EQ(fs::file_size(dir + "/cameras.bin"), 8u + 4 + 4 + 8 + 8 + 8 * 8);
  EXPECT_EQ(fs::file_size(dir + "/images.bin"), 8u + 4 + 7 * 8 + 4 + 8 + 8 + 2 * 24);
  EXPECT_EQ(fs::file_size(dir + "/points3D.bin"), 8u + 8 + 24 + 3 + 8 + 8 + 8);
  const std::string images = testing::ReadFileBytes(dir + "/images.bin");
  EXPECT_EQ(images.substr(8 + 4 + 56 + 4, 8), std::string("abc.png\0", 8));
}

TEST(ColmapModel, TextReaderAcceptsCommentsAndEmptyPointLines) {
  const std::string dir = ScratchDir();
  WriteAll(dir + "/cameras.txt", "# comment\n\n7 SIMPLE_RADIAL 100 50 80 50 25 0.1\r\n");
  WriteAll(dir + "/images.txt",
           "# two lines per image\n"
           "3 1 0 0 0 0.5 0 2 7 a.jpg\n"
           "\n"
           "9 0 1 0 0 1 2 3 7 sub/b.png\n"
           "10.5 20.5 -1 11 12 -1\n");
  const ColmapModel model = ReadColmapModel(dir);
  ASSERT_EQ(model.cameras.size(), 1u);
  EXPECT_EQ(model.cameras.at(7).params, (std::vector<double>{80, 50, 25, 0.1}));
  ASSERT_EQ(model.images.size(), 2u);
  EXPECT_TRUE(model.images.at(3).points2D.empty());
  EXPECT_EQ(model.images.at(9).points2D.size(), 2u);
  EXPECT_EQ(model.images.at(9).point3D_ids[1], kColmapNoPoint3D);
  EXPECT_TRUE(model.points3D.empty());
}

TEST(ColmapModel, TruncatedBinaryFilesFailWithTheFileAndField) {
  const std::string dir = ScratchDir();
  WriteColmapBinary(RandomColmapModel(), dir);
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string path = dir + "/" + file;
    const std::string full = testing::ReadFileBytes(path);
    for (size_t cut = 0; cut < full.size(); cut += 1 + full.size() / 31) {
      WriteAll(path, full.substr(0, cut));
      const std::string error = testing::InputErrorOf([&] { ReadColmapBinary(dir); });
      EXPECT_NE(error.find(file), std::string::npos) << "cut at " << cut << ": " << error;
    }
    WriteAll(path, full);
  }
}

TEST(ColmapModel, GarbledFilesFailClearly) {
  const std::string dir = ScratchDir();
  WriteColmapBinary(RandomColmapModel(), dir);
  std::string cameras = testing::ReadFileBytes(dir + "/cameras.bin");
  cameras[7] = '\x7f';  // an absurd camera count
  WriteAll(dir + "/cameras.bin", cameras);
  EXPECT_NE(testing::InputErrorOf([&] { ReadColmapBinary(dir); }).find("num_cameras"),
            std::string::npos);

  const std::string text = ScratchDir();
  WriteColmapText(RandomColmapModel(), text);
  WriteAll(text + "/cameras.txt", "1 PINHOLE 640 480 500 500 320\n");
  EXPECT_NE(testing::InputErrorOf([&] { ReadColmapText(text); }).find("line 1 PARAMS"),
            std::string::npos);
  WriteAll(text + "/cameras.txt", "1 PINHOLE 640 480 500 500 320 abc\n");
  EXPECT_NE(testing::InputErrorOf([&] { ReadColmapText(text); }).find("'abc'"),
            std::string::npos);
  WriteAll(text + "/cameras.txt", "1 FISH 640 480 500 500 320 240\n");
  EXPECT_NE(testing::InputErrorOf([&] { ReadColmapText(text); }).find("FISH"),
            std::string::npos);
  WriteAll(text + "/cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  WriteAll(text + "/images.txt", "1 1 0 0 0 0 0 0 1 a.png\n");
  EXPECT_NE(testing::InputErrorOf([&] { ReadColmapText(text); }).find("line 2 POINTS2D"),
            std::string::npos);
  WriteAll(text + "/images.txt", "1 1 0 0 0 0 0 0 2 a.png\n\n");
  EXPECT_NE(testing::InputErrorOf([&] { ReadColmapText(text); }).find("CAMERA_ID"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] { ReadColmapModel(ScratchDir()); }).find("cameras"),
            std::string::npos);
}

TEST(ColmapRig, RigRoundTripsThroughBothFormats) {
  const Rig rig = testing::RandomRig(7);
  for (ColmapFormat format : {ColmapFormat::kText, ColmapFormat::kBinary}) {
    const std::string dir = ScratchDir();
    WriteColmapModel(ColmapFromRig(rig), dir, format);
    ExpectRigsEqual(rig, RigFromColmap(ReadColmapModel(dir), dir));
  }
}

TEST(ColmapRig, NamesCamerasByFolderWhenEveryImageHasItsOwn) {
  ColmapModel model = RandomColmapModel();  // "camI/frame_000I.png"
  Rig rig = RigFromColmap(model, "test");
  EXPECT_EQ(rig[0].name, "cam0");
  model.images.begin()->second.name = "cam1/other.png";  // folder cam1 twice
  rig = RigFromColmap(model, "test");
  EXPECT_EQ(rig[0].name, "cam1/other");
  EXPECT_EQ(CameraNameFromImageName("x.JPG"), "x");
  EXPECT_EQ(CameraNameFromImageName("x.raw"), "x.raw");
  EXPECT_EQ(CameraNameFromImageName("a.b/c"), "a.b/c");
}

TEST(ColmapRig, PointsProjectWhereTheModelSays) {
  // The rig's camera projects a point like COLMAP's convention: x = K (R X + t).
  ColmapModel model;
  model.cameras[2] = {2, CameraModelId::kSimplePinhole, 640, 480, {500, 320, 240}};
  ColmapImage image;
  image.id = 1;
  image.camera_id = 2;
  image.name = "a.png";
  const Eigen::Quaterniond q(
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  image.cam_from_world = Rigid3(q, Eigen::Vector3d(0.1, -0.2, 3));
  model.images[1] = image;
  const Rig rig = RigFromColmap(model, "test");
  const Eigen::Vector3d x(0.2, 0.1, 0.4);
  const Eigen::Vector3d c = q * x + Eigen::Vector3d(0.1, -0.2, 3);
  Eigen::Vector2d uv;
  ASSERT_TRUE(rig[0].ProjectWorld(x, &uv));
  EXPECT_NEAR(uv.x(), 500 * c.x() / c.z() + 320, 1e-9);
  EXPECT_NEAR(uv.y(), 500 * c.y() / c.z() + 240, 1e-9);
  EXPECT_THAT(
      rig[0].CenterInWorld(),
      testing::MatrixNear(-(q.conjugate() * Eigen::Vector3d(0.1, -0.2, 3)), 1e-12));
}

// A width that wraps to 640 in 32 bits, and 2^31 / 2^40: refused when read, by value.
TEST(ColmapModel, ImageSizesAreRangeCheckedBeforeNarrowing) {
  for (const uint64_t width :
       {uint64_t{4294967936}, uint64_t{1} << 31, uint64_t{1} << 40}) {
    ColmapModel model = RandomColmapModel();
    model.cameras.begin()->second.width = width;
    const std::string text = ScratchDir() + "/text";
    std::filesystem::create_directories(text);
    WriteColmapText(model, text);
    std::string error = testing::InputErrorOf([&] { ReadColmapText(text); });
    EXPECT_NE(error.find("cameras.txt"), std::string::npos) << error;
    EXPECT_NE(error.find("WIDTH"), std::string::npos) << error;
    EXPECT_NE(error.find(std::to_string(width)), std::string::npos) << error;
    const std::string binary = ScratchDir() + "/binary";
    std::filesystem::create_directories(binary);
    WriteColmapBinary(model, binary);
    error = testing::InputErrorOf([&] { ReadColmapBinary(binary); });
    EXPECT_NE(error.find("cameras.bin"), std::string::npos) << error;
    EXPECT_NE(error.find(std::to_string(width)), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace handlabel
