#include "network/poem/poem_checkpoint.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "core/errors.h"
#include "formats/zip_reader.h"
#include "formats/zip_writer.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_trainer.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// A copy of the checkpoint at `from` with the storage record `record` (an entry name
// ending in "/data/<key>") cut to `bytes` bytes; returns the record's original size.
size_t CopyWithShortRecord(const std::string& from, const std::string& to,
                           const std::string& record, size_t bytes) {
  const ZipReader original = ZipReader::OpenFile(from);
  ZipWriter zip(to);
  size_t original_size = 0;
  for (const ZipEntry& e : original.entries()) {
    std::string data = original.Read(e);
    const std::string suffix = "/data/" + record;
    if (e.name.size() > suffix.size() &&
        e.name.compare(e.name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      original_size = data.size();
      data.resize(std::min(bytes, data.size()));
    }
    zip.Add(e.name, data, ZipMethod::kStored, 64);
  }
  zip.Close();
  return original_size;
}

TEST(PoemCheckpoint, CopyOfTheZipStillLoads) {
  PoemModel model = MakeRandomPoemModel(TinyPoemConfig(2), 3);
  const std::string dir = testing::ScratchDir();
  SavePoemCheckpoint(model, dir + "/tiny.pt");
  ASSERT_GT(CopyWithShortRecord(dir + "/tiny.pt", dir + "/copy.pt", "1", 1u << 30), 0u);
  PoemModel loaded = LoadPoemCheckpoint(dir + "/copy.pt");
  const auto a = PoemStateDict(model);
  const auto b = PoemStateDict(loaded);
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [key, value] : a) EXPECT_TRUE(torch::equal(value, b.at(key))) << key;
}

// A storage record shorter than its tensor: LibTorch would build the tensor over the
// short buffer and read past it (the finite-values check); refused before that.
TEST(PoemCheckpoint, StorageShorterThanItsShapeIsRefused) {
  PoemModel model = MakeRandomPoemModel(TinyPoemConfig(2), 3);
  const std::string dir = testing::ScratchDir();
  SavePoemCheckpoint(model, dir + "/tiny.pt");
  for (const std::string record : {"0", "1", "7"}) {
    const size_t full =
        CopyWithShortRecord(dir + "/tiny.pt", dir + "/short.pt", record, 4);
    ASSERT_GT(full, 4u) << record;
    const std::string error =
        testing::InputErrorOf([&] { LoadPoemCheckpoint(dir + "/short.pt"); });
    EXPECT_NE(error.find("short.pt"), std::string::npos) << error;
    EXPECT_NE(error.find("storage"), std::string::npos) << error;
    EXPECT_NE(error.find("4 bytes in the archive"), std::string::npos) << error;
  }
}

TEST(PoemCheckpoint, NotAnArchiveIsAnInputError) {
  const std::string path = testing::ScratchDir() + "/junk.pt";
  std::ofstream(path) << "not a zip";
  const std::string error = testing::InputErrorOf([&] { LoadPoemCheckpoint(path); });
  EXPECT_NE(error.find("junk.pt"), std::string::npos) << error;
}

// A corrupt latest.json used to surface as a raw JSON exception.
TEST(PoemCheckpoint, CorruptLatestJsonNamesTheFile) {
  const std::string dir = testing::ScratchDir();
  std::ofstream(dir + "/latest.json") << "{\"step\": 12, \"model\": ";
  std::string error = testing::InputErrorOf([&] { LatestPoemCheckpointStep(dir); });
  EXPECT_NE(error.find(dir + "/latest.json"), std::string::npos) << error;
  std::ofstream(dir + "/latest.json", std::ios::trunc)
      << "{\"step\": -4, \"model\": \"m.pt\", \"optimizer\": \"o\"}";
  error = testing::InputErrorOf([&] { LatestPoemCheckpointStep(dir); });
  EXPECT_NE(error.find("'step'"), std::string::npos) << error;
  std::ofstream(dir + "/latest.json", std::ios::trunc)
      << "{\"step\": 4, \"model\": \"m.pt\", \"optimizer\": \"o\"}";
  EXPECT_EQ(LatestPoemCheckpointStep(dir), 4);
}

}  // namespace
}  // namespace handlabel
