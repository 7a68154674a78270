// `capture init|import` in the library: image folders matched by name or index, videos
// with offsets, ranges, every error case, and an interrupted import that resumes.
// Every imported image is compared pixel for pixel with the image it came from.

#include "capture/capture_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "cameras/rig_json.h"
#include "capture/capture_reader.h"
#include "core/errors.h"
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
using testing::SmallRig;

ImageU8 RandomImage(int width = kWidth, int height = kHeight) {
  ImageU8 image(width, height, 3);
  for (uint8_t& v : image.data) v = static_cast<uint8_t>(testing::TestRng()() & 0xff);
  return image;
}

// frames[c][i] = image i of camera c.
using Recording = std::vector<std::vector<ImageU8>>;

Recording RandomRecording(const std::vector<int>& frames_per_camera) {
  Recording r;
  for (int n : frames_per_camera) {
    r.emplace_back();
    for (int i = 0; i < n; ++i) r.back().push_back(RandomImage());
  }
  return r;
}

// DIR/<folder c>/<names[i]>.png
void WriteImageFolders(const std::string& dir, const Recording& recording,
                       const std::vector<std::string>& folders,
                       const std::vector<std::string>& names) {
  for (size_t c = 0; c < recording.size(); ++c) {
    for (size_t i = 0; i < recording[c].size(); ++i) {
      WritePng(dir + "/" + folders[c] + "/" + names[i] + ".png", recording[c][i]);
    }
  }
}

void WriteVideos(const std::string& dir, const Recording& recording) {
  fs::create_directories(dir);
  for (size_t c = 0; c < recording.size(); ++c) {
    testing::WriteLosslessVideo(dir + "/cam" + std::to_string(c) + ".mkv", recording[c]);
  }
}

::testing::AssertionResult SameImage(const ImageU8& a, const ImageU8& b) {
  if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
    return ::testing::AssertionFailure() << "shapes differ";
  }
  for (size_t i = 0; i < a.data.size(); ++i) {
    if (a.data[i] != b.data[i]) {
      return ::testing::AssertionFailure()
             << "byte " << i << ": " << int(a.data[i]) << " vs " << int(b.data[i]);
    }
  }
  return ::testing::AssertionSuccess();
}

// Camera c of imported frame k must be recording[c][source_index(k, c)].
void ExpectFrames(const std::string& capture, const Recording& recording,
                  const std::vector<std::string>& ids,
                  const std::function<int(int, int)>& source_index) {
  const CaptureReader reader(capture);
  ASSERT_EQ(reader.manifest().frames, ids);
  for (int k = 0; k < reader.num_frames(); ++k) {
    for (int c = 0; c < reader.num_cameras(); ++c) {
      EXPECT_TRUE(SameImage(reader.ReadImage(k, c), recording[c][source_index(k, c)]))
          << "frame " << ids[k] << " camera " << c;
    }
  }
}

TEST(CaptureInit, WritesAnEmptyCaptureWithTheRigAndRefusesToOverwriteIt) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  const Rig rig = ReadRigJson(capture + "/rig.json");
  ASSERT_EQ(rig.size(), 3u);
  EXPECT_EQ(rig[2].camera.params(), SmallRig(3)[2].camera.params());
  EXPECT_TRUE(fs::exists(capture + "/colmap/cameras.txt"));
  // No frames yet: the reader says so.
  EXPECT_THAT(InputErrorOf([&] { CaptureReader r(capture); }),
              HasSubstr("at least one frame"));
  CaptureInitOptions init;
  EXPECT_THAT(InputErrorOf([&] { InitCapture(SmallRig(2), {}, capture, init); }),
              HasSubstr("capture.json"));
  init.overwrite = true;
  InitCapture(SmallRig(2), {}, capture, init);
  EXPECT_EQ(ReadRigJson(capture + "/rig.json").size(), 2u);
}

TEST(CaptureInit, ResolvesRigFilesFolders) {
  const std::string dir = ScratchDir();
  fs::create_directories(dir + "/calib_out");
  WriteRigJson(SmallRig(2), dir + "/calib_out/rig.json");
  WriteRig(SmallRig(2), {"colmap-text", dir + "/model"});
  EXPECT_EQ(ResolveRigSpec(dir + "/calib_out", "--rig").path,
            dir + "/calib_out/rig.json");
  EXPECT_EQ(ResolveRigSpec(dir + "/calib_out/rig.json", "--rig").format, "json");
  EXPECT_EQ(ResolveRigSpec(dir + "/model", "--rig").format, "colmap");
  EXPECT_EQ(ResolveRigSpec("colmap-text:" + dir + "/model", "--rig").format,
            "colmap-text");
  EXPECT_THAT(InputErrorOf([&] { ResolveRigSpec(dir, "--rig"); }),
              HasSubstr("a folder holding rig.json"));
}

TEST(CaptureImport, ImageFoldersMatchedByNameRoundTripPixelForPixel) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  const Recording recording = RandomRecording({4, 4, 4});
  const std::vector<std::string> names = {"0100", "0101", "0102", "0103"};
  WriteImageFolders(dir + "/images", recording, {"cam0", "cam1", "cam2"}, names);
  // Another format decodes to the same pixels: camera 2's frame 1 as BMP.
  fs::remove(dir + "/images/cam2/0101.png");
  cv::imwrite(dir + "/images/cam2/0101.bmp", testing::BgrFromRgb(recording[2][1]));
  CaptureImportOptions o;
  o.images_dir = dir + "/images";
  const CaptureImportReport report = ImportCapture(capture, o);
  EXPECT_EQ(report.frames_written, 4);
  EXPECT_TRUE(report.notes.empty()) << report.notes[0];
  ExpectFrames(capture, recording, names, [](int k, int) { return k; });
  // The PNG written is the project's own encoding of those pixels.
  EXPECT_EQ(testing::ReadFileBytes(capture + "/images/cam1/0102.png"),
            EncodePng(recording[1][2]));
}

TEST(CaptureImport, NameMatchingLeavesOutFramesMissingInACameraAndSaysSo) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  const Recording recording = RandomRecording({4, 4, 4});
  WriteImageFolders(dir + "/images", recording, {"cam0", "cam1", "cam2"},
                    {"a", "b", "c", "d"});
  fs::remove(dir + "/images/cam1/c.png");
  fs::create_directories(dir + "/images/notes");  // no such camera: ignored
  CaptureImportOptions o;
  o.images_dir = dir + "/images";
  std::vector<std::string> notes;
  const CaptureImportReport report =
      ImportCapture(capture, o, {[&](const std::string& n) { notes.push_back(n); }, {}});
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_THAT(notes[0], HasSubstr("notes"));
  EXPECT_THAT(notes[1], HasSubstr("cam0 4, cam1 3, cam2 4"));
  EXPECT_THAT(notes[1], HasSubstr("left out"));
  EXPECT_EQ(report.notes, notes);
  ExpectFrames(capture, recording, {"a", "b", "d"},
               [](int k, int) { return k < 2 ? k : 3; });
}

TEST(CaptureImport, IndexMatchingWithMappedFoldersOffsetsStrideAndRange) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  const Recording recording = RandomRecording({6, 6, 6});
  // Each folder names its files its own way; index matching ignores the names.
  for (int c = 0; c < 3; ++c) {
    const std::string folder =
        dir + "/images/" + std::vector<std::string>{"left", "right", "top"}[c];
    for (int i = 0; i < 6; ++i) {
      WritePng(folder + "/img_" + std::to_string(10 * c + i) + ".png", recording[c][i]);
    }
  }
  CaptureImportOptions o;
  o.images_dir = dir + "/images";
  o.match = "index";
  o.source_to_camera = {{"left", "cam0"}, {"right", "cam1"}, {"top", "cam2"}};
  // cam1 started one frame early, cam2 one frame late: timeline frames 1..4 exist in
  // every camera; every second of them from 1.
  o.offsets = {{"cam1", 1}, {"cam2", -1}};
  o.stride = 2;
  const CaptureImportReport report = ImportCapture(capture, o);
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_THAT(report.notes[0], HasSubstr("Timeline frames 1 to 4"));
  const std::vector<int> offset = {0, 1, -1};
  ExpectFrames(capture, recording, {"000001", "000003"},
               [&](int k, int c) { return 1 + 2 * k + offset[c]; });

  // --start / --end / --max-frames select positions of the timeline.
  o.overwrite = true;
  o.stride = 1;
  o.start = 2;
  o.end = 5;
  o.max_frames = 2;
  ImportCapture(capture, o);
  ExpectFrames(capture, recording, {"000002", "000003"},
               [&](int k, int c) { return 2 + k + offset[c]; });
  EXPECT_FALSE(fs::exists(capture + "/images/cam0/000001.png"));  // overwrite cleared
}

TEST(CaptureImport, VideosWithOffsetsAndDifferentLengthsDecodeExactly) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  const Recording recording = RandomRecording({5, 7, 6});
  WriteVideos(dir + "/videos", recording);
  CaptureImportOptions o;
  o.videos_dir = dir + "/videos";
  o.offsets = {{"cam1", 2}};
  std::vector<std::pair<int, int>> progress;
  const CaptureImportReport report =
      ImportCapture(capture, o, {{}, [&](int done, int total) {
                                   progress.push_back({done, total});
                                 }});
  // cam0 has 5 frames, cam1 7 - 2, cam2 6: timeline frames 0..4.
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_THAT(report.notes[0], HasSubstr("cam0 5, cam1 7 (offset 2), cam2 6"));
  EXPECT_THAT(report.notes[0], HasSubstr("Timeline frames 0 to 4"));
  ASSERT_EQ(progress.size(), 6u);
  EXPECT_EQ(progress.front(), std::make_pair(0, 5));
  EXPECT_EQ(progress.back(), std::make_pair(5, 5));
  const std::vector<int> offset = {0, 2, 0};
  ExpectFrames(capture, recording, {"000000", "000001", "000002", "000003", "000004"},
               [&](int k, int c) { return k + offset[c]; });
}

TEST(CaptureImport, ARigCameraWithoutASourceIsAnError) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  WriteImageFolders(dir + "/images", RandomRecording({2, 2}), {"cam0", "cam1"},
                    {"a", "b"});
  CaptureImportOptions o;
  o.images_dir = dir + "/images";
  const std::string error = InputErrorOf([&] { ImportCapture(capture, o); });
  EXPECT_THAT(error, HasSubstr("camera cam2"));
  EXPECT_THAT(error, HasSubstr("a folder cam2/"));
  EXPECT_THAT(error, HasSubstr("--map SOURCE=cam2"));
  o.images_dir.clear();
  WriteVideos(dir + "/videos", RandomRecording({2, 2}));
  o.videos_dir = dir + "/videos";
  EXPECT_THAT(InputErrorOf([&] { ImportCapture(capture, o); }),
              HasSubstr("a video cam2."));
  o.source_to_camera = {{"cam0", "cam9"}};
  EXPECT_THAT(InputErrorOf([&] { ImportCapture(capture, o); }),
              HasSubstr("a camera of the rig (cam0, cam1, cam2)"));
  // --map cam1=cam0 leaves cam1 without a source: the message says where cam1.mkv went
  // (it said "got only cam0.mkv, cam1.mkv", as if cam1.mkv were not there).
  o.source_to_camera = {{"cam1", "cam0"}};
  EXPECT_THAT(
      InputErrorOf([&] { ImportCapture(capture, o); }),
      HasSubstr("field 'camera cam1': expected a video cam1.<mp4|mkv|avi|...> (or "
                "--map SOURCE=cam1), got cam0.mkv (unused), cam1.mkv (--map "
                "cam1=cam0)"));
}

TEST(CaptureImport, AnImageOfAnotherSizeNamesFileCameraAndSizesAndKeepsEarlierFrames) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  Recording recording = RandomRecording({3, 3, 3});
  recording[1][2] = RandomImage(30, 24);
  WriteImageFolders(dir + "/images", recording, {"cam0", "cam1", "cam2"},
                    {"f0", "f1", "f2"});
  CaptureImportOptions o;
  o.images_dir = dir + "/images";
  const std::string error = InputErrorOf([&] { ImportCapture(capture, o); });
  EXPECT_THAT(error, HasSubstr("images/cam1/f2.png"));
  EXPECT_THAT(error, HasSubstr("32x24 (camera cam1 in the rig)"));
  EXPECT_THAT(error, HasSubstr("got 30x24"));
  // The two frames before it are a readable capture.
  ExpectFrames(capture, recording, {"f0", "f1"}, [](int k, int) { return k; });
}

TEST(CaptureImport, AVideoOfAnotherSizeOrUnreadableFailsBeforeWritingAnything) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir, 2);
  WriteVideos(dir + "/videos", RandomRecording({2, 2}));
  testing::WriteLosslessVideo(dir + "/videos/cam1.mkv",
                              {RandomImage(48, 24), RandomImage(48, 24)});
  CaptureImportOptions o;
  o.videos_dir = dir + "/videos";
  std::string error = InputErrorOf([&] { ImportCapture(capture, o); });
  EXPECT_THAT(error, HasSubstr("cam1.mkv"));
  EXPECT_THAT(error, HasSubstr("32x24 (camera cam1 in the rig)"));
  EXPECT_THAT(error, HasSubstr("48x24"));
  EXPECT_FALSE(fs::exists(capture + "/images/cam0"));

  fs::remove(dir + "/videos/cam1.mkv");
  std::ofstream(dir + "/videos/cam1.mp4") << "not a video";
  error = InputErrorOf([&] { ImportCapture(capture, o); });
  EXPECT_THAT(error, HasSubstr("cam1.mp4"));
  EXPECT_THAT(error, HasSubstr("cannot open"));
}

TEST(CaptureImport, ASecondImportNeedsResumeWithTheSameSettingsOrOverwrite) {
  const std::string dir = ScratchDir();
  const std::string capture = InitSmallCapture(dir);
  WriteImageFolders(dir + "/images", RandomRecording({3, 3, 3}), {"cam0", "cam1", "cam2"},
                    {"a", "b", "c"});
  CaptureImportOptions o;
  o.images_dir = dir + "/images";
  ImportCapture(capture, o);
  EXPECT_THAT(InputErrorOf([&] { ImportCapture(capture, o); }),
              HasSubstr("--resume continues"));
  o.resume = true;
  EXPECT_EQ(ImportCapture(capture, o).frames_written, 0);  // nothing left to do
  o.stride = 2;
  EXPECT_THAT(InputErrorOf([&] { ImportCapture(capture, o); }),
              HasSubstr("generator.import"));
  o.resume = false;
  o.overwrite = true;
  EXPECT_EQ(ImportCapture(capture, o).frames_written, 2);
  o.overwrite = false;
  o.offsets = {{"cam1", 1}};  // offsets need index matching
  EXPECT_THAT(InputErrorOf([&] { ImportCapture(capture, o); }), HasSubstr("--offset"));
}

// What a kill leaves at any moment is what is on disk after a frame: capture.json lists
// the frames up to the last checkpoint, all of them complete. An import that stops
// (here: the progress callback throws after 3 frames) keeps its frames, and --resume
// finishes it with the same files as an uninterrupted import.
TEST(CaptureImport, AnInterruptedImportIsReadableAndResumesToTheSameCapture) {
  const std::string dir = ScratchDir();
  const Recording recording = RandomRecording({7, 7, 7});
  WriteVideos(dir + "/videos", recording);
  const std::string reference = InitSmallCapture(dir + "/ref");
  const std::string capture = InitSmallCapture(dir);
  CaptureImportOptions o;
  o.videos_dir = dir + "/videos";
  o.checkpoint_frames = 2;
  ImportCapture(reference, o);

  struct Stop {};
  int checked = 0;
  auto check_then_stop = [&](int done, int) {
    // As another process (or a resumed import after kill -9) sees the folder now.
    const int listed = done - done % o.checkpoint_frames;
    if (listed == 0) {
      EXPECT_THAT(InputErrorOf([&] { CaptureReader r(capture); }),
                  HasSubstr("at least one frame"));
    } else {
      const CaptureReader on_disk(capture);
      EXPECT_EQ(on_disk.num_frames(), listed) << "after " << done << " frames";
      for (int k = 0; k < on_disk.num_frames(); ++k) {
        EXPECT_TRUE(SameImage(on_disk.ReadImage(k, 2), recording[2][k]));
      }
    }
    ++checked;
    if (done == 3) throw Stop{};
  };
  EXPECT_THROW(ImportCapture(capture, o, {{}, check_then_stop}), Stop);
  EXPECT_EQ(checked, 4);  // before frame 1, then after frames 1 to 3
  EXPECT_EQ(CaptureReader(capture).num_frames(), 3);

  o.resume = true;
  const CaptureImportReport report = ImportCapture(capture, o);
  EXPECT_EQ(report.frames_kept, 3);
  EXPECT_EQ(report.frames_written, 4);
  EXPECT_EQ(testing::FilesUnder(capture + "/images"),
            testing::FilesUnder(reference + "/images"));
  EXPECT_EQ(CaptureReader(capture).manifest().frames,
            CaptureReader(reference).manifest().frames);
}

}  // namespace
}  // namespace handlabel
