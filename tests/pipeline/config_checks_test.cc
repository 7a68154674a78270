// Silent acceptance in config files: repeated YAML keys (yaml-cpp finds the first) and
// values checked under their own names.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "pipeline/job_config.h"
#include "pipeline/train_config.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string WriteFile(const std::string& name, const std::string& text) {
  const std::string path = testing::ScratchDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const char* kJob = R"(
name: demo
seed: 7
input: {format: native, path: capture, frames: "0:10"}
network: {weights: weights.pt, batch_size: 2}
output: {dir: labels}
)";

TEST(ConfigChecks, RepeatedYamlKeyIsRefusedAtAnyDepth) {
  EXPECT_NO_THROW(LoadJobConfig(WriteFile("job.yaml", kJob)));
  std::string path = WriteFile("top.yaml", std::string(kJob) + "seed: 8\n");
  std::string error = testing::InputErrorOf([&] { LoadJobConfig(path); });
  EXPECT_THAT(error, HasSubstr(path));
  EXPECT_THAT(error, HasSubstr("'seed'"));
  EXPECT_THAT(error, HasSubstr("each key once"));
  path = WriteFile("nested.yaml",
                   "name: demo\ninput:\n  format: native\n  path: a\n"
                   "  path: b\noutput: {dir: labels}\n");
  error = testing::InputErrorOf([&] { LoadJobConfig(path); });
  EXPECT_THAT(error, HasSubstr("'input.path'"));
}

TEST(ConfigChecks, TrainBatchSizeIsCheckedByItsOwnName) {
  const std::string dir = testing::ScratchDir();
  const auto config = [&](const std::string& train) {
    return WriteFile("train.yaml",
                     "network: tiny\nhand_model: \"\"\n"
                     "data: {preset: dexycb, width: 320, height: 240, seed: 4}\n"
                     "train:\n  steps: 2\n" +
                         train + "  out_dir: " + dir + "/run\n");
  };
  EXPECT_NO_THROW(LoadTrainConfig(config("  batch_size: 2\n")));
  const std::string path = config("  batch_size: -3\n");
  const std::string error = testing::InputErrorOf([&] { LoadTrainConfig(path); });
  EXPECT_THAT(error, HasSubstr(path));
  EXPECT_THAT(error, HasSubstr("train.batch_size"));
  EXPECT_THAT(error, ::testing::Not(HasSubstr("reuse_group")));
  const std::string twice = config("  batch_size: 2\n  batch_size: 4\n");
  EXPECT_THAT(testing::InputErrorOf([&] { LoadTrainConfig(twice); }),
              HasSubstr("train.batch_size"));
  // A batch whose input crops alone exceed the machine's memory is refused when the
  // file is read, before anything is allocated (it ran for minutes without a step).
  const std::string huge = config("  batch_size: 1000000000\n");
  const std::string huge_error = testing::InputErrorOf([&] { LoadTrainConfig(huge); });
  EXPECT_THAT(huge_error, HasSubstr("train.batch_size"));
  EXPECT_THAT(huge_error, HasSubstr("fit in memory"));
  EXPECT_THAT(huge_error, HasSubstr("got 1000000000"));
}

}  // namespace
}  // namespace handlabel
