// Damaged recordings in `capture import` (issue 46): a truncated JPEG and a video with
// corrupted bytes were imported as garbage frames with status "complete"; videos of 15
// and 30 fps were paired by index without a word. Now the damaged frame fails the
// import naming the file and the frame (the frames before it stay in the capture), and
// mixed frame rates are refused unless allowed, with a note naming both videos.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "capture/capture_import.h"
#include "capture/capture_reader.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "image/image_file.h"
#include "tests/capture/capture_import_fixture.h"
#include "tests/capture/video_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::InitSmallCapture;
using testing::InputErrorOf;
using testing::kHeight;
using testing::kWidth;
using testing::ScratchDir;

// A smooth picture (compresses like a camera image) that changes with `t`.
ImageU8 Picture(int t, int width = kWidth, int height = kHeight) {
  ImageU8 image(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = static_cast<uint8_t>((x * 7 + y * 5 + t * 9 + c * 60) & 0xff);
  return image;
}

std::string ImportStatus(const std::string& capture) {
  return CaptureReader(capture).manifest().generator.value("import_status", "");
}

TEST(CaptureImportDamage, ATruncatedJpegFailsTheImportNamingTheFile) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir, 2);
  for (int c = 0; c < 2; ++c) {
    for (int i = 0; i < 3; ++i) {
      WriteJpeg(dir + "/images/cam" + std::to_string(c) + "/f" + std::to_string(i) +
                    ".jpg",
                Picture(i));
    }
  }
  const std::string damaged = dir + "/images/cam1/f1.jpg";
  fs::resize_file(damaged, fs::file_size(damaged) * 2 / 3);
  CaptureImportOptions o;
  o.images_dir = dir + "/images";
  const std::string error = InputErrorOf([&] { ImportCapture(capture, o); });
  EXPECT_THAT(error, HasSubstr(damaged + ": field 'data': expected a valid JPEG"));
  EXPECT_THAT(error, HasSubstr("Premature end of JPEG file"));
  const CaptureReader reader(capture);
  EXPECT_EQ(reader.manifest().frames, std::vector<std::string>{"f0"});
  EXPECT_THAT(ImportStatus(capture), HasSubstr("failed: " + damaged));
}

// MPEG-4 part 2 videos of 40 frames (a key frame every 12: OpenCV's writer default);
// bytes in the middle of cam1's are overwritten. The frames before the damage are
// imported; the import stops at the first frame that depends on it, naming the video
// and the frame. The same videos undamaged import completely (no false alarm).
TEST(CaptureImportDamage, ACorruptVideoFrameFailsTheImportNamingVideoAndFrame) {
  const std::string dir = ScratchDir();
  const int frames = 40;
  std::vector<ImageU8> pictures;
  for (int t = 0; t < frames; ++t) pictures.push_back(Picture(t, 64, 48));
  fs::create_directories(dir + "/videos");
  for (const char* camera : {"cam0", "cam1"}) {
    testing::WriteMpeg4Video(dir + "/videos/" + camera + ".avi", pictures);
  }
  CaptureInitOptions init;
  Rig rig;
  for (int c = 0; c < 2; ++c) {
    rig.Add({"cam" + std::to_string(c), Camera::Pinhole(60, 60, 31.5, 23.5, 64, 48),
             Rigid3()});
  }
  InitCapture(rig, {}, dir + "/clean", init);
  CaptureImportOptions o;
  o.videos_dir = dir + "/videos";
  EXPECT_EQ(ImportCapture(dir + "/clean", o).frames_written, frames);
  EXPECT_EQ(ImportStatus(dir + "/clean"), "complete");

  const std::string video = dir + "/videos/cam1.avi";
  std::string bytes = ReadFileBytes(video, "video");
  for (size_t i = bytes.size() / 2; i < bytes.size() / 2 + 400; ++i) bytes[i] ^= 0x5a;
  std::ofstream(video, std::ios::binary | std::ios::trunc) << bytes;
  InitCapture(rig, {}, dir + "/damaged", init);
  const std::string error = InputErrorOf([&] { ImportCapture(dir + "/damaged", o); });
  EXPECT_THAT(error, HasSubstr(video + " frame "));
  EXPECT_THAT(error, HasSubstr("expected a frame FFmpeg decodes without error (camera "
                               "cam1), got damaged since frame "));
  const int kept = CaptureReader(dir + "/damaged").num_frames();
  EXPECT_GT(kept, 0);
  EXPECT_LT(kept, frames);
  EXPECT_THAT(ImportStatus(dir + "/damaged"), HasSubstr("failed: " + video));
}

TEST(CaptureImportDamage, VideosOfDifferentFrameRatesAreRefusedUnlessAllowed) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir, 2);
  fs::create_directories(dir + "/videos");
  testing::WriteLosslessVideo(dir + "/videos/cam0.mkv", {Picture(0), Picture(1)}, 30);
  testing::WriteLosslessVideo(dir + "/videos/cam1.mkv", {Picture(0), Picture(1)}, 15);
  CaptureImportOptions o;
  o.videos_dir = dir + "/videos";
  const std::string error = InputErrorOf([&] { ImportCapture(capture, o); });
  EXPECT_THAT(error, HasSubstr("--videos: field 'frame rate': expected videos of one "
                               "frame rate"));
  EXPECT_THAT(error, HasSubstr("got cam1.mkv (camera cam1) runs at 15 fps, cam0.mkv "
                               "(camera cam0) at 30 fps"));
  EXPECT_FALSE(fs::exists(capture + "/images/cam0"));  // refused before any frame

  o.allow_mixed_fps = true;
  const CaptureImportReport report = ImportCapture(capture, o);
  EXPECT_EQ(report.frames_written, 2);
  ASSERT_FALSE(report.notes.empty());
  EXPECT_THAT(report.notes[0], HasSubstr("runs at 15 fps"));
  EXPECT_THAT(report.notes[0], HasSubstr("--allow-mixed-fps"));
}

}  // namespace
}  // namespace handlabel
