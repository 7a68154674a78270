#include "core/file_lock.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

TEST(FileLock, SecondWriterOfAFolderIsRefusedNamingFolderAndHolder) {
  const std::string dir = testing::ScratchDir() + "/folder";
  fs::create_directories(dir);
  {
    const FileLock first = LockFolderForWriting(dir, "capture import", "--capture", "");
    const std::string error = testing::InputErrorOf(
        [&] { LockFolderForWriting(dir, "detect --capture", "--capture", ""); });
    EXPECT_THAT(error, HasSubstr("--capture"));
    EXPECT_THAT(error, HasSubstr("no other process is writing (" + dir + ")"));
    EXPECT_THAT(error, HasSubstr("in use by capture import, pid " +
                                 std::to_string(::getpid()) + " on host "));
  }
  // Released with the first lock.
  EXPECT_NO_THROW(LockFolderForWriting(dir, "detect --capture", "--capture", ""));
  EXPECT_THAT(ReadLockHolder(FolderLockPath(dir)), HasSubstr("detect --capture, pid"));
}

TEST(FileLock, AFolderThatDoesNotExistIsNamed) {
  const std::string dir = testing::ScratchDir() + "/missing";
  EXPECT_THAT(testing::InputErrorOf([&] { LockFolderForWriting(dir, "x", "--out", ""); }),
              HasSubstr(FolderLockPath(dir)));
  EXPECT_FALSE(fs::exists(dir));
}

// A holder killed with SIGKILL leaves its lock file, but the kernel has released the
// flock: the next writer gets the folder.
TEST(FileLock, LockOfAKilledProcessDoesNotBlock) {
  const std::string dir = testing::ScratchDir() + "/folder";
  fs::create_directories(dir);
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  if (child == 0) {
    const FileLock held = LockFolderForWriting(dir, "train", "child", "");
    const char byte = 1;
    if (write(ready[1], &byte, 1) != 1) _exit(2);
    pause();
    _exit(0);
  }
  char byte = 0;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);
  EXPECT_TRUE(LockedByOthers(FolderLockPath(dir)));
  EXPECT_THAT(testing::InputErrorOf([&] { LockFolderForWriting(dir, "train", "p", ""); }),
              HasSubstr("in use by train, pid " + std::to_string(child)));
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(fs::exists(FolderLockPath(dir)));
  EXPECT_FALSE(LockedByOthers(FolderLockPath(dir)));
  EXPECT_NO_THROW(LockFolderForWriting(dir, "train", "p", ""));
  close(ready[0]);
  close(ready[1]);
}

}  // namespace
}  // namespace handlabel
