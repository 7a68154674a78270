// The job YAML fuzz corpus replayed in the ordinary build (tests/fuzz_replay.h).

#include <gtest/gtest.h>

#include <fstream>

#include "pipeline/job_config.h"
#include "tests/fuzz_replay.h"

namespace handlabel {
namespace {

TEST(JobYaml, FuzzCorpusSmoke) {
  const std::string path = testing::ScratchDir() + "/job.yaml";
  EXPECT_GE(testing::ReplayFuzzCorpus(
                "job_yaml",
                [&](const std::string& bytes) {
                  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
                  LoadJobConfig(path);
                }),
            4);
}

// A list used as a mapping key used to escape as a yaml-cpp conversion error.
TEST(JobYaml, NonTextKeyIsAnInputError) {
  const std::string path = testing::ScratchDir() + "/job.yaml";
  std::ofstream(path) << "name: a\n? [x, y]\n: 3\noutput: {dir: o}\n";
  const std::string error = testing::InputErrorOf([&] { LoadJobConfig(path); });
  EXPECT_NE(error.find("plain text keys"), std::string::npos) << error;
}

}  // namespace
}  // namespace handlabel
