#include <gtest/gtest.h>

#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::CommandResult;
using testing::RunHandlabelCommand;

TEST(FitCommand, HelpDescribesTheOptions) {
  const CommandResult r = RunHandlabelCommand({"fit", "--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* option : {"--capture", "--init", "--evidence", "--masks", "--loss",
                             "--ignore-views", "--overlay", "--threads"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
}

TEST(FitCommand, MissingCaptureIsAnErrorNamingIt) {
  const std::string dir = testing::ScratchDir();
  const CommandResult r =
      RunHandlabelCommand({"fit", "--capture", dir + "/none", "--out", dir + "/out"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("none"), std::string::npos) << r.err;
}

TEST(FitCommand, BadLossIsAnError) {
  const std::string dir = testing::ScratchDir();
  const CommandResult r = RunHandlabelCommand(
      {"fit", "--capture", dir, "--out", dir + "/out", "--loss", "magic"});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--loss"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace handlabel
