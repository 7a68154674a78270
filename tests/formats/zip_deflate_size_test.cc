// A deflate entry declaring more bytes than deflate can produce from its compressed
// size is refused before anything is allocated for it (found by torch_archive_fuzz:
// a 1841-byte archive whose 431-byte data.pkl declared 3.5 GB, allocated in full).

#include <gtest/gtest.h>

#include <string>

#include "core/errors.h"
#include "formats/torch_archive.h"
#include "formats/zip_reader.h"
#include "formats/zip_writer.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

std::string ReadError(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ZipDeflateSize, FuzzerArchiveDeclaringGigabytesIsRefusedBeforeAllocating) {
  const std::string path = std::string(HANDLABEL_SOURCE_DIR) +
                           "/fuzz/corpus/torch_archive/oom-deflate-declares-3.5GB";
  const std::string error = ReadError([&] { TorchArchive(path).Tensors(); });
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("entry 'state_dict/data.pkl'"), std::string::npos) << error;
  EXPECT_NE(error.find("from 431 bytes (at most 1032 times"), std::string::npos) << error;
  EXPECT_NE(error.find("got 3523215791 bytes declared"), std::string::npos) << error;
}

// Zeros at level 9 come close to deflate's limit (about 1029:1) and still read; one
// byte per 1032 more than the limit allows is refused, one less is not (it then fails
// only because the stream is shorter than declared).
TEST(ZipDeflateSize, LimitIsDeflatesOwnLargestExpansion) {
  const std::string path = testing::ScratchDir() + "/zeros.zip";
  const std::string zeros(4 << 20, '\0');
  ZipWriterOptions options;
  options.deflate_level = 9;
  {
    ZipWriter zip(path, options);
    zip.Add("zeros", zeros, ZipMethod::kDeflate);
    zip.Close();
  }
  const ZipReader zip = ZipReader::OpenFile(path);
  ZipEntry entry = zip.entries().at(0);
  ASSERT_GT(entry.uncompressed_size, 1000 * entry.compressed_size);
  EXPECT_EQ(zip.Read(entry), zeros);
  entry.uncompressed_size = 1032 * (entry.compressed_size + 1);
  EXPECT_NE(ReadError([&] { zip.Read(entry); }).find("deflate can reach"),
            std::string::npos);
  entry.uncompressed_size -= 1;
  const std::string within = ReadError([&] { zip.Read(entry); });
  EXPECT_NE(within, "");
  EXPECT_EQ(within.find("deflate can reach"), std::string::npos) << within;
}

}  // namespace
}  // namespace handlabel
