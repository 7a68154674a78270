// The training config fuzz corpus replayed in the ordinary build (tests/fuzz_replay.h),
// through the whole reader: the YAML layer the fuzz target covers and the checks after
// it (rig presets, generator, samples, trainer, network overrides).

#include <gtest/gtest.h>

#include <fstream>

#include "pipeline/train_config.h"
#include "tests/fuzz_replay.h"

namespace handlabel {
namespace {

TEST(TrainConfig, FuzzCorpusSmoke) {
  const std::string path = testing::ScratchDir() + "/train.yaml";
  EXPECT_GE(testing::ReplayFuzzCorpus(
                "train_config",
                [&](const std::string& bytes) {
                  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
                  LoadTrainConfig(path);
                }),
            4);
}

// network_overrides whose key is a list, or whose text is not UTF-8, are input errors
// naming the field (they used to escape as yaml-cpp / JSON library exceptions).
TEST(TrainConfig, OddNetworkOverridesAreInputErrors) {
  const std::string path = testing::ScratchDir() + "/train.yaml";
  std::ofstream(path) << "network_overrides:\n  ? [a, b]\n  : 3\ntrain: {out_dir: r}\n";
  std::string error = testing::InputErrorOf([&] { LoadTrainConfig(path); });
  EXPECT_NE(error.find("network_overrides"), std::string::npos) << error;
  std::ofstream(path, std::ios::trunc)
      << "network_overrides: {backbone: \"\xff\xfe\"}\ntrain: {out_dir: r}\n";
  error = testing::InputErrorOf([&] { LoadTrainConfig(path); });
  EXPECT_NE(error.find("network_overrides"), std::string::npos) << error;
}

}  // namespace
}  // namespace handlabel
