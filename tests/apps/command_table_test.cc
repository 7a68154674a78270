#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "apps/commands.h"
#include "tests/apps/run_command.h"

namespace handlabel {
namespace {

using testing::RunHandlabelCommand;

TEST(CommandTable, HelpListsEverySubcommand) {
  const testing::CommandResult r = RunHandlabelCommand({"--help"});
  EXPECT_EQ(r.status, 0);
  ASSERT_FALSE(AllCommands().empty());
  for (const Command& c : AllCommands()) {
    EXPECT_NE(r.out.find(std::string("  ") + c.name), std::string::npos) << c.name;
  }
}

TEST(CommandTable, UnknownSubcommandExitsWithStatus2AndNamesIt) {
  const testing::CommandResult r = RunHandlabelCommand({"frobnicate"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'frobnicate'"), std::string::npos) << r.err;
}

TEST(CommandTable, NoArgumentsIsAUsageError) {
  EXPECT_EQ(RunHandlabelCommand({}).status, 2);
}

TEST(CommandTable, VersionPrintsVersionHashAndDependencies) {
  const testing::CommandResult r = RunHandlabelCommand({"version"});
  EXPECT_EQ(r.status, 0);
  for (const char* needle :
       {"handlabel 0.", "git ", "Eigen", "Ceres", "OpenCV", "LibTorch", "oneTBB"}) {
    EXPECT_NE(r.out.find(needle), std::string::npos) << needle << " in\n" << r.out;
  }
}

TEST(CommandTable, BadOptionOfASubcommandIsAUsageError) {
  const testing::CommandResult r = RunHandlabelCommand({"version", "--no-such-flag"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no-such-flag"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace handlabel
