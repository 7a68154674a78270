// One writer per capture with real processes of the built binary (issue 46: an
// --overwrite import beside a running one ended "complete, 60 of 60 frames" with views
// missing on disk): while an import runs, a second import (--overwrite or --resume)
// and `detect --capture` exit 1 naming the folder and the holder, and the first
// completes intact; the lock of a killed import does not block its --resume.

#include <signal.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "capture/capture_reader.h"
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
  const std::string mark = "pid " + std::to_string(pid) + " ";
  for (int i = 0; i < 6000; ++i) {
    if (ReadLockHolder(FolderLockPath(dir)).find(mark) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
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

}  // namespace
}  // namespace handlabel
