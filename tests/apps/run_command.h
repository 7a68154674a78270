#pragma once
// Runs `handlabel <args...>` in-process, as the shell would, capturing its output; or
// as a real child process of the built binary (SpawnHandlabel), for tests of several
// processes at once.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "apps/commands.h"
#include "core/file_lock.h"

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

// Starts build/apps/handlabel with `args`; stdout and stderr are appended to `log`.
// With `file_size_limit` > 0, the child cannot write a file beyond that many bytes
// (RLIMIT_FSIZE; the write fails with EFBIG, SIGXFSZ ignored): a disk that fills up.
// `env` (name, value) pairs are set in the child's environment on top of the test's.
inline pid_t SpawnHandlabel(const std::vector<std::string>& args, const std::string& log,
                            rlim_t file_size_limit = 0,
                            const std::vector<std::pair<std::string, std::string>>& env = {}) {
  // Everything the child needs is built before fork: the child only calls
  // async-signal-safe functions.
  std::string binary = std::string(HANDLABEL_BINARY_DIR) + "/apps/handlabel";
  std::vector<std::string> copy = args;
  std::vector<char*> argv = {binary.data()};
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> variables;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string variable = *e;
    const std::string name = variable.substr(0, variable.find('='));
    bool replaced = false;
    for (const auto& set : env) replaced = replaced || set.first == name;
    if (!replaced) variables.push_back(variable);
  }
  for (const auto& [name, value] : env) variables.push_back(name + "=" + value);
  std::vector<char*> envp;
  for (std::string& v : variables) envp.push_back(v.data());
  envp.push_back(nullptr);

  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    if (file_size_limit > 0) {
      signal(SIGXFSZ, SIG_IGN);  // kept across exec
      const rlimit limit{file_size_limit, file_size_limit};
      if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(126);
    }
    execve(binary.c_str(), argv.data(), envp.data());
    _exit(127);
  }
  return pid;
}

// The child's exit status, or minus the signal that ended it.
inline int WaitForExit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

// Waits (up to 15 s) until `pid` has recorded itself in the lock file `lock_path`
// (core/file_lock.h): it holds the folder. False if it never did.
inline bool WaitUntilHolding(pid_t pid, const std::string& lock_path) {
  const std::string mark = "pid " + std::to_string(pid) + " ";
  for (int i = 0; i < 7500; ++i) {
    if (ReadLockHolder(lock_path).find(mark) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

}  // namespace handlabel::testing
