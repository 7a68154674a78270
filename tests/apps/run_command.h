#pragma once
// Runs `handlabel <args...>` in-process, as the shell would, capturing its output.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "apps/commands.h"

namespace handlabel::testing {

struct CommandResult {
  int status;
  std::string out;
  std::string err;
};

inline CommandResult RunHandlabelCommand(std::vector<std::string> args) {
  args.insert(args.begin(), "handlabel");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const int status = RunHandlabel(static_cast<int>(argv.size()), argv.data());
  return {status, ::testing::internal::GetCapturedStdout(),
          ::testing::internal::GetCapturedStderr()};
}

}  // namespace handlabel::testing
