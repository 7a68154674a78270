#include <gtest/gtest.h>

#include <set>
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

// Each command once (a merge once listed synth twice in --help).
TEST(CommandTable, EveryCommandIsListedOnce) {
  const std::string out = RunHandlabelCommand({"--help"}).out;
  std::set<std::string> names;
  for (const Command& c : AllCommands()) {
    EXPECT_TRUE(names.insert(c.name).second) << c.name << " twice in the table";
    const std::string line = std::string("\n  ") + c.name + " ";
    const size_t first = out.find(line);
    ASSERT_NE(first, std::string::npos) << c.name;
    EXPECT_EQ(out.find(line, first + 1), std::string::npos) << c.name << " twice in\n"
                                                            << out;
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
