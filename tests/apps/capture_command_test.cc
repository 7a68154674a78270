// `handlabel capture init|import` end to end: a synthetic capture turned into one video
// per camera (lossless FFV1, written here with OpenCV's VideoWriter) and imported again
// labels exactly like the capture it came from; image folders round-trip byte for byte;
// errors and help.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/capture_reader.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/capture/video_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::FilesUnder;
using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

// DIR/<camera>.mkv with every frame of the capture.
void WriteCaptureVideos(const std::string& capture, const std::string& dir) {
  const CaptureReader reader(capture);
  fs::create_directories(dir);
  for (int c = 0; c < reader.num_cameras(); ++c) {
    std::vector<ImageU8> frames;
    for (int f = 0; f < reader.num_frames(); ++f)
      frames.push_back(reader.ReadImage(f, c));
    testing::WriteLosslessVideo(dir + "/" + reader.rig()[c].name + ".mkv", frames);
  }
}

// Stands in for `handlabel detect` (another step of the walk-through): gives `to` the
// detections of `from` (same frame ids and cameras).
void CopyDetections(const std::string& from, const std::string& to) {
  fs::copy(from + "/detections", to + "/detections", fs::copy_options::recursive);
  fs::remove_all(to + "/detections/masks");
  const std::string manifest_path = to + "/capture.json";
  nlohmann::json manifest = nlohmann::json::parse(testing::ReadFileBytes(manifest_path));
  manifest["files"]["detections"] = "detections/{frame}.json";
  std::ofstream(manifest_path) << manifest.dump(2) << "\n";
}

// A fit-only job (detections, no masks) with overlays, labelling DIR/capture into
// DIR/<output>. The job hash covers the capture's path, so both runs label the same
// path: the image capture first, then the imported one moved there.
std::string WriteFitJob(const std::string& dir, const std::string& output) {
  const std::string path = dir + "/" + output + ".yaml";
  std::ofstream(path) << "name: import\nseed: 5\nhand_model: capsule\n"
                      << "input: {format: native, path: capture}\n"
                      << "network: {threads: 2}\n"
                      << "refine: {mode: always}\n"
                      << "evidence: {keypoints_2d: files, keypoint_files: detections, "
                         "masks: none}\n"
                      << "output: {dir: " << output
                      << ", overlays: true, evaluate: false}\n";
  return path;
}

TEST(CaptureCommand, AVideoImportLabelsExactlyLikeTheImageCaptureItCameFrom) {
  const std::string dir = testing::ScratchDir();
  const std::string source = dir + "/capture";
  const std::string imported = dir + "/imported";
  testing::WriteTestCapture(source, 2, 17);
  WriteCaptureVideos(source, dir + "/recording");

  testing::CommandResult r =
      RunHandlabelCommand({"capture", "init", "--rig", source, "--out", imported});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("8 cameras"));
  r = RunHandlabelCommand(
      {"capture", "import", "--capture", imported, "--videos", dir + "/recording"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("imported 2 frames"));
  // Every image decodes to the source's pixels, so the PNG files are the same bytes.
  EXPECT_EQ(FilesUnder(imported + "/images"), FilesUnder(source + "/images"));
  CopyDetections(source, imported);

  r = RunHandlabelCommand({"label", "--job", WriteFitJob(dir, "from_images"), "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  fs::rename(source, dir + "/source");
  fs::rename(imported, source);
  r = RunHandlabelCommand({"label", "--job", WriteFitJob(dir, "from_videos"), "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;

  const auto labels = FilesUnder(dir + "/from_images/labels");
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_TRUE(FilesUnder(dir + "/from_videos/labels") == labels)
      << "labels differ (not printed: each holds every vertex)";
  // Overlays draw each label on the imported pixels: same frames, same images.
  const auto overlays = FilesUnder(dir + "/from_images/overlays");
  ASSERT_EQ(overlays.size(), 2u * 8u);
  EXPECT_TRUE(FilesUnder(dir + "/from_videos/overlays") == overlays);
}

TEST(CaptureCommand, ImageFoldersImportAndOptionsReachTheLibrary) {
  const std::string dir = testing::ScratchDir();
  const std::string source = dir + "/source";
  testing::WriteTestCapture(source, 4, 3);
  const std::string capture = dir + "/capture";
  // A side that is neither is refused by the one hand-side parser, naming the field.
  const testing::CommandResult bad =
      RunHandlabelCommand({"capture", "init", "--rig", "json:" + source + "/rig.json",
                           "--out", capture, "--hand-side", "both"});
  EXPECT_NE(bad.status, 0);
  EXPECT_THAT(bad.err,
              HasSubstr("'hand_side': expected \"right\" or \"left\", got both"));
  ASSERT_EQ(
      RunHandlabelCommand({"capture", "init", "--rig", "json:" + source + "/rig.json",
                           "--out", capture, "--hand-side", "left"})
          .status,
      0);
  // cam01's images one frame late: its file 000001 is timeline frame 0.
  const testing::CommandResult r = RunHandlabelCommand(
      {"capture", "import", "--capture", capture, "--images", source + "/images",
       "--match", "index", "--offset", "cam01=1", "--stride", "2", "--threads", "1"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("note: frames per camera"));
  const CaptureReader reader(capture);
  EXPECT_EQ(reader.manifest().hand_side, "left");
  ASSERT_EQ(reader.manifest().frames, (std::vector<std::string>{"000000", "000002"}));
  EXPECT_EQ(testing::ReadFileBytes(capture + "/images/cam01/000002.png"),
            testing::ReadFileBytes(source + "/images/cam01/000003.png"));
  EXPECT_EQ(testing::ReadFileBytes(capture + "/images/cam00/000002.png"),
            testing::ReadFileBytes(source + "/images/cam00/000002.png"));
}

TEST(CaptureCommand, ErrorsAndUsage) {
  const std::string dir = testing::ScratchDir();
  testing::CommandResult r = RunHandlabelCommand({"capture", "--help"});
  EXPECT_EQ(r.status, 0);
  EXPECT_THAT(r.out, HasSubstr("docs/real-captures.md"));
  r = RunHandlabelCommand({"capture", "import", "--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* flag :
       {"--images", "--videos", "--map", "--offset", "--stride", "--resume", "--match"}) {
    EXPECT_THAT(r.out, HasSubstr(flag));
  }
  EXPECT_EQ(RunHandlabelCommand({"capture"}).status, 2);
  EXPECT_EQ(RunHandlabelCommand({"capture", "frobnicate"}).status, 2);
  EXPECT_EQ(RunHandlabelCommand({"capture", "import", "--videos", dir}).status, 2);

  r = RunHandlabelCommand({"capture", "init", "--rig", dir, "--out", dir + "/c"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("--rig"));

  testing::WriteTestCapture(dir + "/source", 1, 1);
  ASSERT_EQ(RunHandlabelCommand(
                {"capture", "init", "--rig", dir + "/source", "--out", dir + "/c"})
                .status,
            0);
  fs::remove_all(dir + "/source/images/cam03");
  r = RunHandlabelCommand(
      {"capture", "import", "--capture", dir + "/c", "--images", dir + "/source/images"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("camera cam03"));
  r = RunHandlabelCommand({"capture", "import", "--capture", dir + "/c", "--images",
                           dir + "/source/images", "--offset", "cam00"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("CAMERA=N"));
}

}  // namespace
}  // namespace handlabel
