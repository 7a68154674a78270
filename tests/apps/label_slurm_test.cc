// Integration test: a real single-node SLURM cluster on localhost (scripts/local-slurm,
// Debian slurm-wlm + munge) runs the labeling job as the array job of
// jobs/slurm/label_array.sbatch; the merged result equals a single-process run.

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::RunHandlabelCommand;

// Runs a shell command; returns its exit status and stdout.
int Shell(const std::string& command, std::string* out = nullptr) {
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  std::string text;
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof(buffer), pipe)) text.append(buffer, n);
  const int status = pclose(pipe);
  if (out) *out = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool Installed(const char* program) {
  return Shell(std::string("PATH=$PATH:/usr/sbin:/sbin command -v ") + program +
               " > /dev/null 2>&1") == 0;
}

// Brings the cluster down however the test ends.
struct LocalSlurm {
  std::string script, state;
  ~LocalSlurm() {
    Shell(script + " down " + state + " > /dev/null 2>&1");
    std::error_code ignored;
    std::filesystem::remove_all(state, ignored);
  }
};

TEST(LabelSlurm, ArrayJobOnARealLocalClusterMergesToTheSingleProcessRun) {
  for (const char* program : {"slurmctld", "slurmd", "munged", "sbatch"}) {
    if (!Installed(program)) {
      GTEST_SKIP() << program << " is not installed: the SLURM integration test needs "
                   << "Debian's slurm-wlm and munge (scripts/install-deps installs them)";
    }
  }
  if (geteuid() != 0)
    GTEST_SKIP() << "scripts/local-slurm runs munged and slurmd as root";

  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 7, 13);
  const std::string single = testing::WriteTestJob(dir, "single", "capture", "single");
  const std::string array = testing::WriteTestJob(dir, "array", "capture", "array");
  ASSERT_EQ(RunHandlabelCommand({"label", "--job", single, "--quiet"}).status, 0);

  const std::string source = HANDLABEL_SOURCE_DIR;
  // A short state folder: munge's socket path must stay under 108 bytes.
  char state[] = "/tmp/hl-slurm-XXXXXX";
  ASSERT_NE(mkdtemp(state), nullptr);
  LocalSlurm cluster{source + "/scripts/local-slurm", state};
  std::string conf;
  ASSERT_EQ(Shell("PATH=$PATH:/usr/sbin:/sbin " + cluster.script + " up " +
                      cluster.state + " 2>&1",
                  &conf),
            0)
      << conf;
  conf.erase(conf.find_last_not_of("\n") + 1);
  conf = conf.substr(conf.rfind('\n') + 1);  // the last line is the config path

  // Three array tasks; each reads SLURM_ARRAY_TASK_ID / _COUNT and labels its shard.
  // (Polling squeue instead of sbatch --wait, which polls only every 10 s.)
  const std::string env = "SLURM_CONF=" + conf + " ";
  std::string job_id;
  ASSERT_EQ(Shell(env + "HANDLABEL=" + HANDLABEL_BINARY_DIR +
                      "/apps/handlabel sbatch --parsable --array=0-2 --cpus-per-task=1 "
                      "--mem=500M --output=" +
                      cluster.state + "/task-%A_%a.log " + source +
                      "/jobs/slurm/label_array.sbatch " + array + " 2>&1",
                  &job_id),
            0)
      << job_id;
  job_id.erase(job_id.find_last_not_of("\n") + 1);
  std::string queued = "?";
  for (int i = 0; i < 1200 && !queued.empty(); ++i) {
    usleep(100000);
    ASSERT_EQ(Shell(env + "squeue -h -j " + job_id + " -o %T 2>&1", &queued), 0)
        << queued;
  }
  std::string task_logs;
  for (const auto& e : fs::directory_iterator(cluster.state)) {
    if (e.path().filename().string().rfind("task-", 0) == 0)
      task_logs += testing::ReadFileBytes(e.path());
  }
  ASSERT_TRUE(queued.empty()) << "the array job did not finish in 120 s:\n" << task_logs;
  for (const char* shard : {"shard 0/3", "shard 1/3", "shard 2/3"}) {
    EXPECT_THAT(task_logs, ::testing::HasSubstr(shard));
  }

  const auto merged = RunHandlabelCommand({"merge", "--job", array});
  ASSERT_EQ(merged.status, 0) << merged.out << merged.err;
  EXPECT_EQ(testing::FilesUnder(dir + "/array/labels"),
            testing::FilesUnder(dir + "/single/labels"));
  EXPECT_EQ(testing::FilesUnder(dir + "/array/labels").size(), 7u);
  EXPECT_EQ(testing::ReadFileBytes(dir + "/array/manifest.json"),
            testing::ReadFileBytes(dir + "/single/manifest.json"));
}

}  // namespace
}  // namespace handlabel
