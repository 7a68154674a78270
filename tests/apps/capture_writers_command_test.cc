// One writer per capture, and per `detect --images` folder, with real processes of
// the built binary (issue 46: an --overwrite import beside a running one ended
// "complete, 60 of 60 frames" with views missing on disk; two detects, full and lite,
// both exited 0): while an import runs, a second import (--overwrite or --resume) and
// `detect --capture` exit 1 naming the folder and the holder, and the first completes
// intact; a second detect beside a running one likewise; the lock of a killed import
// does not block its --resume.

#include <signal.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capture/capture_reader.h"
#include "core/data_dir.h"
#include "core/file_lock.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::SpawnHandlabel;
using testing::WaitForExit;

constexpr int kFrames = 12;

// Waits until `pid` has recorded itself in the folder's lock (it holds the folder).
bool WaitUntilHolding(pid_t pid, const std::string& dir) {
  return testing::WaitUntilHolding(pid, FolderLockPath(dir));
}

bool MediapipeModelsPresent() {
  return std::filesystem::exists(
             ShippedModelPath("mediapipe/palm_detection_full.tflite")) &&
         std::filesystem::exists(ShippedModelPath("mediapipe/hand_landmark_lite.tflite"));
}

// Every file directly in `dir` (not the lock file, not folders), by name, with its
// bytes.
std::map<std::string, std::string> FilesOf(const std::string& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && name != ".handlabel.lock")
      files[name] = testing::ReadFileBytes(e.path().string());
  }
  return files;
}

// Every frame of `source` is in `capture`, image for image.
void ExpectSameFrames(const std::string& source, const std::string& capture) {
  const CaptureReader from(source), to(capture);
  ASSERT_EQ(to.manifest().frames, from.manifest().frames);
  EXPECT_EQ(to.manifest().generator.value("import_status", ""), "complete");
  for (int f = 0; f < to.num_frames(); ++f) {
    for (int c = 0; c < to.num_cameras(); ++c) {
      EXPECT_EQ(to.ReadImage(f, c).data, from.ReadImage(f, c).data) << f << " " << c;
    }
  }
}

class CaptureWriters : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::ScratchDir();
    source_ = dir_ + "/source";
    capture_ = dir_ + "/capture";
    testing::WriteTestCapture(source_, kFrames, 21);
    ASSERT_EQ(testing::RunHandlabelCommand(
                  {"capture", "init", "--rig", source_, "--out", capture_})
                  .status,
              0);
  }
  std::vector<std::string> Import(const std::string& extra = "") const {
    std::vector<std::string> args = {"capture",   "import",   "--capture",
                                     capture_,    "--images", source_ + "/images",
                                     "--threads", "1"};
    if (!extra.empty()) args.push_back(extra);
    return args;
  }
  std::string dir_, source_, capture_;
};

TEST_F(CaptureWriters, SecondImportAndDetectAreRefusedWhileAnImportRuns) {
  const pid_t first = SpawnHandlabel(Import(), dir_ + "/first.log");
  ASSERT_TRUE(WaitUntilHolding(first, capture_))
      << testing::ReadFileBytes(dir_ + "/first.log");
  kill(first, SIGSTOP);  // keeps the lock while the others try
  ASSERT_TRUE(LockedByOthers(FolderLockPath(capture_)));
  const std::string holder = "in use by capture import, pid " + std::to_string(first);
  int n = 0;
  for (const auto& args :
       {Import("--overwrite"), Import("--resume"),
        std::vector<std::string>{"detect", "--capture", capture_, "--overwrite"}}) {
    const std::string log = dir_ + "/other" + std::to_string(n++) + ".log";
    EXPECT_EQ(WaitForExit(SpawnHandlabel(args, log)), 1) << args[1];
    const std::string err = testing::ReadFileBytes(log);
    EXPECT_THAT(err, HasSubstr("no other process is writing (" + capture_ + ")"));
    EXPECT_THAT(err, HasSubstr(holder));
  }
  kill(first, SIGCONT);
  EXPECT_EQ(WaitForExit(first), 0) << testing::ReadFileBytes(dir_ + "/first.log");
  ExpectSameFrames(source_, capture_);
}

TEST_F(CaptureWriters, LockOfAKilledImportDoesNotBlockItsResume) {
  const pid_t killed = SpawnHandlabel(Import(), dir_ + "/killed.log");
  ASSERT_TRUE(WaitUntilHolding(killed, capture_));
  kill(killed, SIGKILL);
  EXPECT_EQ(WaitForExit(killed), -SIGKILL);
  const testing::CommandResult resumed = testing::RunHandlabelCommand(Import("--resume"));
  EXPECT_EQ(resumed.status, 0) << resumed.err;
  ExpectSameFrames(source_, capture_);
}

// `detect --capture` (full model) beside a running one (lite): the second exits 1
// naming the holder; the first's detections are those of a detect run alone. (A
// 3-frame capture of its own: the detector is the slow part.)
TEST_F(CaptureWriters, SecondDetectIsRefusedWhileADetectRuns) {
  if (!MediapipeModelsPresent()) GTEST_SKIP() << "run scripts/fetch-mediapipe-models";
  constexpr int kDetectFrames = 3;
  const std::string capture = dir_ + "/small";
  testing::WriteTestCapture(capture, kDetectFrames, 5);
  std::filesystem::copy(capture, dir_ + "/alone",
                        std::filesystem::copy_options::recursive);
  const auto detect = [](const std::string& folder, const std::string& model) {
    return std::vector<std::string>{"detect", "--capture", folder, "--model",
                                    model,    "--threads", "1",    "--overwrite"};
  };
  const pid_t first = SpawnHandlabel(detect(capture, "full"), dir_ + "/first.log");
  ASSERT_TRUE(WaitUntilHolding(first, capture))
      << testing::ReadFileBytes(dir_ + "/first.log");
  kill(first, SIGSTOP);
  ASSERT_TRUE(LockedByOthers(FolderLockPath(capture)));
  EXPECT_EQ(WaitForExit(SpawnHandlabel(detect(capture, "lite"), dir_ + "/second.log")),
            1);
  const std::string err = testing::ReadFileBytes(dir_ + "/second.log");
  EXPECT_THAT(err, HasSubstr("no other process is writing (" + capture + ")"));
  EXPECT_THAT(err, HasSubstr("in use by detect --capture, pid " + std::to_string(first)));
  kill(first, SIGCONT);
  EXPECT_EQ(WaitForExit(first), 0) << testing::ReadFileBytes(dir_ + "/first.log");
  ASSERT_EQ(testing::RunHandlabelCommand(detect(dir_ + "/alone", "full")).status, 0);
  const auto files = FilesOf(capture + "/detections");
  EXPECT_EQ(files.size(), static_cast<size_t>(kDetectFrames));
  EXPECT_THAT(files.begin()->second, HasSubstr("\"mediapipe_hands\""));  // not synth's
  EXPECT_EQ(files, FilesOf(dir_ + "/alone/detections"));
  EXPECT_TRUE(CaptureReader(capture).Has(kFileDetections));
}

// `detect --images` into a folder another detect --images writes: refused naming the
// holder; the first writes a record per image and its summary.
TEST_F(CaptureWriters, SecondDetectIntoTheSameImagesFolderIsRefused) {
  if (!MediapipeModelsPresent()) GTEST_SKIP() << "run scripts/fetch-mediapipe-models";
  std::vector<std::string> first_args = {"detect", "--threads", "1", "--images"};
  const CaptureReader source(source_);
  for (int f = 0; f < kFrames; ++f) first_args.push_back(source.Path(kFileImage, f));
  const std::string out = dir_ + "/det";
  first_args.insert(first_args.end(), {"--out", out});
  const pid_t first = SpawnHandlabel(first_args, dir_ + "/first.log");
  ASSERT_TRUE(WaitUntilHolding(first, out))
      << testing::ReadFileBytes(dir_ + "/first.log");
  kill(first, SIGSTOP);
  const std::vector<std::string> second = {"detect", "--images", first_args[4], "--out",
                                           out,      "--model",  "lite"};
  EXPECT_EQ(WaitForExit(SpawnHandlabel(second, dir_ + "/second.log")), 1);
  const std::string err = testing::ReadFileBytes(dir_ + "/second.log");
  EXPECT_THAT(err, HasSubstr("--out: expected a folder no other process is writing"));
  EXPECT_THAT(err, HasSubstr("in use by detect --images, pid " + std::to_string(first)));
  kill(first, SIGCONT);
  EXPECT_EQ(WaitForExit(first), 0) << testing::ReadFileBytes(dir_ + "/first.log");
  const auto files = FilesOf(out);
  EXPECT_EQ(files.size(), static_cast<size_t>(kFrames + 1));  // + summary.json
  const nlohmann::json summary = nlohmann::json::parse(files.at("summary.json"));
  EXPECT_EQ(summary["model"], "full");
  EXPECT_EQ(summary["images"].size(), static_cast<size_t>(kFrames));
}

}  // namespace
}  // namespace handlabel
