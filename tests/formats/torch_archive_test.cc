#include "formats/torch_archive.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "formats/zip_reader.h"
#include "formats/zip_writer.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using namespace std::string_literals;

std::string DataPath(const std::string& rel) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/" + rel;
}

// tests/data/npy/state_dict.pt (weight: float32 (2, 3, 4) in a 24-float storage "0")
// with `from` replaced by `to` in its data.pkl.
std::string ArchiveWithPickleEdit(const std::string& from, const std::string& to) {
  const ZipReader original = ZipReader::OpenFile(DataPath("npy/state_dict.pt"));
  const std::string path = testing::ScratchDir() + "/storage_edit.pt";
  ZipWriter zip(path);
  for (const ZipEntry& e : original.entries()) {
    std::string data = original.Read(e);
    if (e.name == "state_dict/data.pkl") {
      const size_t at = data.find(from);
      EXPECT_NE(at, std::string::npos);
      data.replace(at, from.size(), to);
    }
    zip.Add(e.name, data, ZipMethod::kStored, 64);
  }
  zip.Close();
  return path;
}

std::string TensorsError(const std::string& path) {
  try {
    TorchArchive(path).Tensors();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TorchArchive, RefusesViewsOutsideTheirStorage) {
  using namespace std::string_literals;
  EXPECT_EQ(TensorsError(ArchiveWithPickleEdit("cpuq\x07K\x18"s, "cpuq\x07K\x18"s)), "");
  // The storage claims 16 floats but its entry holds 24.
  std::string error =
      TensorsError(ArchiveWithPickleEdit("cpuq\x07K\x18"s, "cpuq\x07K\x10"s));
  EXPECT_NE(error.find("16 elements of float32"), std::string::npos) << error;
  EXPECT_NE(error.find("state_dict/data/0"), std::string::npos) << error;
  // Size (2, 3, 5) with strides (12, 4, 1) reaches element 24 of 24.
  error =
      TensorsError(ArchiveWithPickleEdit("K\x02K\x03K\x04\x87"s, "K\x02K\x03K\x05\x87"s));
  EXPECT_NE(error.find("a view inside the storage"), std::string::npos) << error;
  // A stride of 127 jumps out of the storage at once.
  error =
      TensorsError(ArchiveWithPickleEdit("K\x0cK\x04K\x01\x87"s, "K\x7fK\x04K\x01\x87"s));
  EXPECT_NE(error.find("stride"), std::string::npos) << error;
}

// A storage count of 2^62 + 24 floats is 96 bytes modulo 2^64, the size of the real
// entry: a multiplied check passes it, and then a (2, 3, 5) view (one element past
// the 24 stored) looks inside the claimed storage and is read past the entry's end.
TEST(TorchArchive, StorageCountThatWrapsAroundIsRefused) {
  const std::string huge_count = "\x8a\x08\x18\x00\x00\x00\x00\x00\x00\x40"s;
  std::string path = ArchiveWithPickleEdit("cpuq\x07K\x18"s, "cpuq\x07"s + huge_count);
  std::string error = TensorsError(path);
  EXPECT_NE(error.find("state_dict/data/0"), std::string::npos) << error;
  EXPECT_NE(error.find("storage"), std::string::npos) << error;
  path = ArchiveWithPickleEdit("K\x02K\x03K\x04\x87"s, "K\x02K\x03K\x05\x87"s);
  // (the same view with an honest count is refused by the view check)
  EXPECT_NE(TensorsError(path).find("a view inside the storage"), std::string::npos);
}

// A storage of 24 floats whose entry holds 95 bytes (not a whole number of floats).
TEST(TorchArchive, EntryOfPartialElementsIsRefused) {
  const ZipReader original = ZipReader::OpenFile(DataPath("npy/state_dict.pt"));
  const std::string path = testing::ScratchDir() + "/partial.pt";
  ZipWriter zip(path);
  for (const ZipEntry& e : original.entries()) {
    std::string data = original.Read(e);
    if (e.name == "state_dict/data/0") data.resize(95);
    zip.Add(e.name, data, ZipMethod::kStored, 64);
  }
  zip.Close();
  const std::string error = TensorsError(path);
  EXPECT_NE(error.find("24 elements of float32"), std::string::npos) << error;
  EXPECT_NE(error.find("95 bytes"), std::string::npos) << error;
}

}  // namespace
}  // namespace handlabel
