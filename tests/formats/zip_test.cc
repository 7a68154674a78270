#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "formats/npy.h"
#include "formats/npz.h"
#include "formats/zip_reader.h"
#include "formats/zip_writer.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

std::string Fixture(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/npy/" + name;
}

std::string RandomBytes(size_t n, bool compressible) {
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(testing::Uniform(0, compressible ? 4 : 256));
  return s;
}

TEST(ZipReader, ReadsNumpySavezStoredAndCompressed) {
  for (const char* file : {"stored.npz", "compressed.npz"}) {
    const NamedArrays arrays = ReadNpzFile(Fixture(file));
    ASSERT_EQ(arrays.size(), 2u) << file;
    EXPECT_EQ(arrays[0].first, "a");
    EXPECT_EQ(arrays[1].first, "b");
    EXPECT_EQ(arrays[0].second.ToDoubles(), ReadNpyFile(Fixture("f8_c.npy")).ToDoubles());
    EXPECT_EQ(arrays[1].second.ToInt64s(), ReadNpyFile(Fixture("i4_v2.npy")).ToInt64s());
  }
}

TEST(ZipReader, ReadsPythonZip64Records) {
  const ZipReader zip = ZipReader::OpenFile(Fixture("zip64.zip"));
  ASSERT_EQ(zip.entries().size(), 2u);
  EXPECT_EQ(zip.entries()[1].method, 8);
  for (const char* name : {"stored.npy", "deflated.npy"}) {
    EXPECT_EQ(ParseNpy(zip.Read(name), name).ToDoubles(),
              ReadNpyFile(Fixture("f8_c.npy")).ToDoubles());
  }
}

TEST(ZipReader, ReadsTorchSaveArchive) {
  const ZipReader zip = ZipReader::OpenFile(Fixture("state_dict.pt"));
  ASSERT_NE(zip.Find("state_dict/data.pkl"), nullptr);
  ASSERT_NE(zip.Find("state_dict/data/0"), nullptr);
  EXPECT_EQ(zip.Read("state_dict/data/0").size(), 24u * 4);
  EXPECT_EQ(zip.Read("state_dict/version"), "3\n");
}

struct WriterCase {
  ZipMethod method;
  bool zip64;
  uint32_t alignment;
};

class ZipRoundTrip : public ::testing::TestWithParam<WriterCase> {};

TEST_P(ZipRoundTrip, ReaderReturnsWhatWriterWrote) {
  const std::string path = testing::ScratchDir() + "/a.zip";
  ZipWriterOptions options;
  options.force_zip64 = GetParam().zip64;
  std::vector<std::pair<std::string, std::string>> files = {
      {"empty", ""},
      {"small.txt", "hello"},
      {"dir/noise.bin", RandomBytes(70000, false)},
      {"dir/repetitive.bin", RandomBytes(200000, true)},
      {"caf\xc3\xa9.txt", "utf-8 name"}};
  {
    ZipWriter zip(path, options);
    for (const auto& [name, data] : files) {
      zip.Add(name, data, GetParam().method, GetParam().alignment);
    }
    zip.Close();
  }
  const std::string bytes = testing::ReadFileBytes(path);
  const ZipReader zip = ZipReader::OpenFile(path);
  ASSERT_EQ(zip.entries().size(), files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    const ZipEntry& e = zip.entries()[i];
    EXPECT_EQ(e.name, files[i].first);
    EXPECT_EQ(zip.Read(e), files[i].second) << e.name;
    if (GetParam().alignment > 1 && e.method == 0) {
      const size_t data_start = bytes.find(files[i].second, e.local_header_offset + 30);
      if (!files[i].second.empty()) {
        EXPECT_EQ(data_start % GetParam().alignment, 0u);
      }
    }
  }
  if (GetParam().method == ZipMethod::kDeflate) {
    EXPECT_LT(zip.Find("dir/repetitive.bin")->compressed_size, 100000u);
  }
  // The same reader over the bytes in memory agrees.
  EXPECT_EQ(ZipReader::FromBytes(bytes, "mem").Read("small.txt"), "hello");
}

INSTANTIATE_TEST_SUITE_P(Variants, ZipRoundTrip,
                         ::testing::Values(WriterCase{ZipMethod::kStored, false, 0},
                                           WriterCase{ZipMethod::kDeflate, false, 0},
                                           WriterCase{ZipMethod::kStored, true, 0},
                                           WriterCase{ZipMethod::kDeflate, true, 0},
                                           WriterCase{ZipMethod::kStored, false, 64},
                                           WriterCase{ZipMethod::kStored, true, 64}));

TEST(ZipWriter, IsDeterministic) {
  const std::string dir = testing::ScratchDir();
  for (const char* name : {"/a.zip", "/b.zip"}) {
    ZipWriter zip(dir + name);
    zip.Add("x", "payload", ZipMethod::kDeflate);
    zip.Close();
  }
  EXPECT_EQ(testing::ReadFileBytes(dir + "/a.zip"),
            testing::ReadFileBytes(dir + "/b.zip"));
}

TEST(Npz, WriteReadRoundTrip) {
  const std::string path = testing::ScratchDir() + "/m.npz";
  std::vector<double> v(12);
  for (auto& x : v) x = testing::Gaussian(1);
  const NamedArrays arrays = {{"v", NdArray::FromDoubles({4, 3}, v.data())},
                              {"side", NdArray::FromText("left")}};
  WriteNpzFile(path, arrays, ZipMethod::kDeflate);
  const NamedArrays back = ReadNpzFile(path);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].first, "v");
  EXPECT_EQ(back[0].second.ToDoubles(), v);
  EXPECT_EQ(back[1].second.ToText(), "left");
}

// A disk that fills up while an .npz is written (a file size limit here: the write fails
// with EFBIG): an InputError naming the file, the earlier file intact and no temporary
// left (issue 46: `model convert` and `export --format npz` left "<file>.tmp" behind).
TEST(Npz, AFailedWriteKeepsTheOldFileAndLeavesNoTemporary) {
  const std::string dir = testing::ScratchDir();
  const std::string path = dir + "/m.npz";
  const double one = 1.0;
  WriteNpzFile(path, {{"v", NdArray::FromDoubles({1}, &one)}});
  const std::string before = testing::ReadFileBytes(path);
  std::vector<double> big(100000);
  for (auto& x : big) x = testing::Gaussian(1);
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto previous_handler = signal(SIGXFSZ, SIG_IGN);
  const rlimit limit{64 * 1024, old.rlim_max};
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0);
  std::string error;
  try {
    WriteNpzFile(path, {{"big", NdArray::FromDoubles({100000}, big.data())}});
  } catch (const InputError& e) {
    error = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  signal(SIGXFSZ, previous_handler);
  EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
  EXPECT_NE(error.find("write failed"), std::string::npos) << error;
  EXPECT_EQ(testing::ReadFileBytes(path), before);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename(), "m.npz");
    ++files;
  }
  EXPECT_EQ(files, 1);
}

std::string ZipErrorOf(const std::string& bytes, const std::string& entry = "") {
  try {
    const ZipReader zip = ZipReader::FromBytes(bytes, "bad.zip");
    for (const ZipEntry& e : zip.entries()) {
      if (entry.empty() || e.name == entry) zip.Read(e);
    }
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ZipReader, RejectsCorruptArchivesWithClearErrors) {
  const std::string good = testing::ReadFileBytes(Fixture("compressed.npz"));
  EXPECT_EQ(ZipErrorOf(good), "");
  EXPECT_NE(ZipErrorOf("not a zip at all, just some text").find("end of central"),
            std::string::npos);
  EXPECT_NE(ZipErrorOf(good.substr(0, good.size() / 2)).find("bad.zip"),
            std::string::npos);
  // Flip a byte inside the first entry's compressed data: CRC or deflate must fail.
  std::string flipped = good;
  flipped[80] ^= 0x55;
  EXPECT_NE(ZipErrorOf(flipped).find("entry 'a.npy'"), std::string::npos)
      << ZipErrorOf(flipped);
  // Every truncation either opens nothing or fails cleanly; never crashes.
  for (size_t n = 0; n < good.size(); n += 7) ZipErrorOf(good.substr(0, n));
  // A central directory claiming a huge entry is refused before allocating.
  std::string huge = testing::ReadFileBytes(Fixture("stored.npz"));
  const size_t cd = huge.find("PK\x01\x02");
  for (int k = 0; k < 4; ++k) huge[cd + 24 + k] = '\xF0';  // uncompressed size
  ZipLimits limits;
  limits.max_entry_bytes = 1 << 20;
  try {
    ZipReader::FromBytes(huge, "huge.zip", limits).Read("a.npy");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("declared"), std::string::npos) << e.what();
  }
}

// The npz fuzz target's corpus (fuzz/corpus/npz_reader), read as LoadHandModel reads
// .npz entries: nothing but success or InputError.
TEST(ZipReader, FuzzCorpusSmoke) {
  const std::string dir = std::string(HANDLABEL_SOURCE_DIR) + "/fuzz/corpus/npz_reader";
  int inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string bytes = testing::ReadFileBytes(entry.path().string());
    ++inputs;
    try {
      if (LooksLikeZip(bytes)) {
        const ZipReader zip = ZipReader::FromBytes(bytes, "corpus.npz");
        for (const ZipEntry& e : zip.entries()) {
          const std::string data = zip.Read(e);
          if (!ParseNpyHeader(data, e.name).is_object) ParseNpy(data, e.name);
        }
      } else {
        ParseNpy(bytes, "corpus.npy");
      }
    } catch (const InputError&) {
    }
  }
  EXPECT_GE(inputs, 15);
}

}  // namespace
}  // namespace handlabel
