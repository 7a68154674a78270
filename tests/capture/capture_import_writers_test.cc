// One writer per capture (issue 46): an import holds the capture folder's lock, so a
// second import (--overwrite or --resume) or `capture init --overwrite` meanwhile is
// refused naming the folder and the holder, and the first completes intact. And an
// --overwrite import does not keep listing files that describe the old images.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cameras/rig_json.h"
#include "capture/capture_import.h"
#include "capture/capture_manifest_file.h"
#include "capture/capture_reader.h"
#include "core/errors.h"
#include "core/file_lock.h"
#include "image/image_file.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::InputErrorOf;
using ::testing::Not;
using testing::ScratchDir;

constexpr int kWidth = 16;
constexpr int kHeight = 12;
const std::vector<std::string> kCameras = {"cam0", "cam1"};

std::string InitTwoCameraCapture(const std::string& dir) {
  Rig rig;
  for (size_t c = 0; c < kCameras.size(); ++c) {
    RigCamera cam;
    cam.name = kCameras[c];
    cam.camera = Camera::Pinhole(20, 20, 7.5, 5.5, kWidth, kHeight);
    cam.cam_from_world.translation = Eigen::Vector3d(0.1 * c, 0, 0);
    rig.Add(cam);
  }
  CaptureInitOptions init;
  init.rig_source = "test rig";
  const std::string capture = dir + "/capture";
  InitCapture(rig, {}, capture, init);
  return capture;
}

// DIR/<camera>/<i>.png, `frames` images of one grey level per camera.
std::string WriteRecording(const std::string& dir, int frames, uint8_t level) {
  for (const std::string& camera : kCameras) {
    for (int i = 0; i < frames; ++i) {
      ImageU8 image(kWidth, kHeight, 3);
      std::fill(image.data.begin(), image.data.end(), static_cast<uint8_t>(level + i));
      WritePng(dir + "/" + camera + "/" + std::to_string(100 + i) + ".png", image);
    }
  }
  return dir;
}

// Every listed frame has its images on disk, and the import says it is complete.
void ExpectCompleteCapture(const std::string& capture, int frames) {
  const CaptureReader reader(capture);
  ASSERT_EQ(reader.num_frames(), frames);
  EXPECT_EQ(reader.manifest().generator.value("import_status", ""), "complete");
  for (int f = 0; f < reader.num_frames(); ++f) {
    for (int c = 0; c < reader.num_cameras(); ++c) {
      EXPECT_EQ(reader.ReadImage(f, c).width, kWidth);
    }
  }
}

TEST(CaptureImportWriters, SecondWriterIsRefusedWhileAnImportRunsAndTheFirstCompletes) {
  const std::string dir = ScratchDir();
  const std::string capture = InitTwoCameraCapture(dir);
  CaptureImportOptions first;
  first.images_dir = WriteRecording(dir + "/a", 6, 10);
  first.checkpoint_frames = 2;
  CaptureImportOptions overwrite;
  overwrite.images_dir = WriteRecording(dir + "/b", 4, 100);
  overwrite.overwrite = true;
  CaptureImportOptions resume = first;
  resume.resume = true;
  std::vector<std::string> refusals;
  // Halfway through the first import (it holds the folder), the others try. flock
  // locks belong to open files: a second lock in one process conflicts like another
  // process's would.
  auto others_try = [&](int done, int) {
    if (done != 3) return;
    refusals.push_back(InputErrorOf([&] { ImportCapture(capture, overwrite); }));
    refusals.push_back(InputErrorOf([&] { ImportCapture(capture, resume); }));
    refusals.push_back(InputErrorOf([&] {
      CaptureInitOptions init;
      init.rig_source = "test rig";
      init.overwrite = true;
      InitCapture(ReadRigJson(capture + "/rig.json"), {}, capture, init);
    }));
  };
  const CaptureImportReport report = ImportCapture(capture, first, {{}, others_try});
  EXPECT_EQ(report.frames_written, 6);
  ASSERT_EQ(refusals.size(), 3u);
  for (const std::string& refusal : refusals) {
    EXPECT_THAT(refusal, HasSubstr(capture));
    EXPECT_THAT(refusal, HasSubstr("no other process is writing"));
    EXPECT_THAT(refusal,
                HasSubstr("in use by capture import, pid " + std::to_string(::getpid())));
  }
  ExpectCompleteCapture(capture, 6);
  EXPECT_EQ(CaptureReader(capture).ReadImage(5, 1).data[0], 15);  // the first's
  // Released at the end: the overwrite runs now.
  EXPECT_EQ(ImportCapture(capture, overwrite).frames_written, 4);
  ExpectCompleteCapture(capture, 4);
}

// A re-import with --overwrite replaces the images; detections, keypoints, masks and
// ground truth computed from the old ones must not stay listed (a fit-only job then
// labelled the new images from the old 2D).
TEST(CaptureImportWriters, OverwriteUnlistsFilesOfTheOldImagesAndSaysSo) {
  const std::string dir = ScratchDir();
  const std::string capture = InitTwoCameraCapture(dir);
  CaptureImportOptions o;
  o.images_dir = WriteRecording(dir + "/a", 3, 10);
  ImportCapture(capture, o);
  CaptureManifest manifest = ReadCaptureManifest(capture, "test");
  manifest.files[kFileDetections] = "detections/{frame}.json";
  manifest.files[kFileKeypoints] = "keypoints/{frame}.json";
  manifest.files[kFileMask] = "masks/{camera}/{frame}.png";
  manifest.files[kFileGroundTruth] = "ground_truth/{frame}.json";
  WriteCaptureManifest(capture, manifest);
  fs::create_directories(capture + "/detections");
  const std::string kept_file = capture + "/detections/100.json";
  std::ofstream(kept_file) << "{}";

  // Sources that give no frame: nothing is dropped.
  CaptureImportOptions empty = o;
  empty.overwrite = true;
  empty.start = 50;
  EXPECT_THAT(InputErrorOf([&] { ImportCapture(capture, empty); }),
              HasSubstr("at least one frame"));
  EXPECT_EQ(ReadCaptureManifest(capture, "test").files.size(), 5u);

  o.images_dir = WriteRecording(dir + "/b", 2, 100);
  o.overwrite = true;
  std::vector<std::string> notes;
  const CaptureImportReport report = ImportCapture(
      capture, o, {[&](const std::string& note) { notes.push_back(note); }, {}});
  EXPECT_EQ(report.frames_written, 2);
  const CaptureManifest after = ReadCaptureManifest(capture, "test");
  ASSERT_EQ(after.files.size(), 1u);
  EXPECT_EQ(after.files.count(kFileImage), 1u);
  ASSERT_EQ(notes.size(), 1u);
  for (const char* kind :
       {"detections (detections/{frame}.json)", "keypoints", "mask", "ground_truth"}) {
    EXPECT_THAT(notes[0], HasSubstr(kind));
  }
  EXPECT_TRUE(fs::exists(kept_file));  // unlisted, not deleted
  // The reader sees no 2D of the old images.
  EXPECT_FALSE(CaptureReader(capture).Has(kFileDetections));
  // A second --overwrite has nothing more to drop and says nothing.
  notes.clear();
  ImportCapture(capture, o, {[&](const std::string& note) { notes.push_back(note); }, {}});
  for (const std::string& note : notes) EXPECT_THAT(note, Not(HasSubstr("no longer")));
}

}  // namespace
}  // namespace handlabel
