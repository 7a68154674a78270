// The torch archive fuzz corpus replayed in the ordinary build (tests/fuzz_replay.h).

#include <gtest/gtest.h>

#include <fstream>

#include "formats/torch_archive.h"
#include "tests/fuzz_replay.h"

namespace handlabel {
namespace {

TEST(TorchArchive, FuzzCorpusSmoke) {
  const std::string path = testing::ScratchDir() + "/fuzz.pt";
  EXPECT_GE(testing::ReplayFuzzCorpus(
                "torch_archive",
                [&](const std::string& bytes) {
                  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
                  TorchArchive(path).Tensors();
                }),
            2);
}

}  // namespace
}  // namespace handlabel
