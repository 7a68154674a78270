#include "formats/sha256.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "tests/test_util.h"

namespace handlabel {
namespace {

TEST(Sha256, KnownVectors) {
  // FIPS 180-4 examples.
  EXPECT_EQ(Sha256Hex(""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, FileHashMatchesSha256sum) {
  const std::string path = testing::ScratchDir() + "/weights.bin";
  std::string data(200000 + testing::TestRng()() % 1000, '\0');
  for (char& c : data) c = static_cast<char>(testing::TestRng()());
  std::ofstream(path, std::ios::binary) << data;
  FILE* pipe = popen(("sha256sum " + path).c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char out[65] = {};
  ASSERT_EQ(fread(out, 1, 64, pipe), 64u);
  pclose(pipe);
  EXPECT_EQ(Sha256OfFile(path), std::string(out));
}

}  // namespace
}  // namespace handlabel
