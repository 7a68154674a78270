// The PNG fast path (libdeflate + our unfiltering) against OpenCV's PNG reader on
// files libpng wrote, with every filter type present; and what it leaves to libpng.
#include "image/png_decode_fast.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::ScratchDir;
using testing::TestRng;

// Smooth ramps, noise and flat runs: libpng's adaptive filter choice then uses all five
// filter types over the set.
ImageU8 MixedImage(int w, int h, int c) {
  ImageU8 image(w, h, c);
  std::mt19937_64& rng = TestRng();
  for (int y = 0; y < h; ++y) {
    const int kind = y % 4;
    for (int x = 0; x < w; ++x) {
      for (int k = 0; k < c; ++k) {
        const int ramp = (x * 3 + y * 5 + k * 40) & 255;
        image.at(x, y, k) = static_cast<uint8_t>(kind == 0   ? ramp
                                                 : kind == 1 ? rng() & 255
                                                 : kind == 2 ? 77
                                                             : ramp ^ (rng() & 7));
      }
    }
  }
  return image;
}

int Paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b),
            pc = std::abs(p - c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

void PutChunk(const std::string& type, const std::string& data, std::string* png) {
  for (int shift = 24; shift >= 0; shift -= 8) png->push_back(char(data.size() >> shift));
  const std::string body = type + data;
  png->append(body);
  const uLong crc = crc32(0, reinterpret_cast<const Bytef*>(body.data()), body.size());
  for (int shift = 24; shift >= 0; shift -= 8) png->push_back(char(crc >> shift));
}

// A PNG made here with row y filtered by filter type y % 5 (the spec's forward
// filters) and zlib: libpng's writer (image/image.cc) only uses Sub, so this is how the
// decoder meets all five.
std::string PngWithEveryFilter(const ImageU8& image) {
  const int c = image.channels;
  const size_t stride = size_t(image.width) * c;
  std::string raw;
  std::vector<int> prev(stride, 0);
  for (int y = 0; y < image.height; ++y) {
    const uint8_t* row = &image.at(0, y);
    const int f = y % 5;
    raw.push_back(char(f));
    for (size_t i = 0; i < stride; ++i) {
      const int a = i >= size_t(c) ? row[i - c] : 0, b = prev[i];
      const int d = i >= size_t(c) ? prev[i - c] : 0;
      const int predicted = f == 0   ? 0
                            : f == 1 ? a
                            : f == 2 ? b
                            : f == 3 ? (a + b) / 2
                                     : Paeth(a, b, d);
      raw.push_back(char(uint8_t(row[i] - predicted)));
    }
    prev.assign(row, row + stride);
  }
  std::vector<Bytef> z(compressBound(raw.size()));
  uLongf z_size = z.size();
  EXPECT_EQ(compress2(z.data(), &z_size, reinterpret_cast<const Bytef*>(raw.data()),
                      raw.size(), 6),
            Z_OK);
  std::string ihdr;
  for (const uint32_t v : {uint32_t(image.width), uint32_t(image.height)}) {
    for (int shift = 24; shift >= 0; shift -= 8) ihdr.push_back(char(v >> shift));
  }
  ihdr += std::string{8, char(c == 1 ? 0 : c == 3 ? 2 : 6), 0, 0, 0};
  std::string png = "\x89PNG\r\n\x1a\n";
  PutChunk("IHDR", ihdr, &png);
  PutChunk("IDAT", std::string(reinterpret_cast<const char*>(z.data()), z_size), &png);
  PutChunk("IEND", "", &png);
  return png;
}

// OpenCV's decoding of `path` as our layout (RGB / RGBA order).
ImageU8 ReadWithOpenCv(const std::string& path) {
  cv::Mat m = cv::imread(path, cv::IMREAD_UNCHANGED);
  EXPECT_EQ(m.depth(), CV_8U);
  ImageU8 image(m.cols, m.rows, m.channels());
  for (int y = 0; y < m.rows; ++y) {
    const uint8_t* row = m.ptr<uint8_t>(y);
    for (int x = 0; x < m.cols; ++x) {
      for (int k = 0; k < m.channels(); ++k) {
        const int from = m.channels() >= 3 && k < 3 ? 2 - k : k;  // BGR(A) -> RGB(A)
        image.at(x, y, k) = row[x * m.channels() + from];
      }
    }
  }
  return image;
}

TEST(PngDecodeFast, MatchesOpenCvOnEveryChannelCountFilterAndLevel) {
  const std::string dir = ScratchDir();
  int n = 0;
  for (const int c : {1, 3, 4}) {
    for (const auto& [w, h] :
         std::vector<std::pair<int, int>>{{1, 1}, {7, 5}, {333, 41}}) {
      const ImageU8 image = MixedImage(w, h, c);
      // Every filter (made here) and libpng's own files at four zlib levels.
      std::vector<std::string> files = {PngWithEveryFilter(image)};
      for (const int level : {0, 1, 6, 9}) {
        const std::string path = dir + "/libpng" + std::to_string(n++) + ".png";
        WritePng(path, image, {level});
        files.push_back(ReadFileBytes(path, "PNG file"));
      }
      for (const std::string& bytes : files) {
        const std::string path = dir + "/p" + std::to_string(n++) + ".png";
        WriteFileAtomically(path, bytes);
        ImageU8 fast;
        ASSERT_TRUE(DecodePngFast(bytes, &fast)) << path;
        EXPECT_EQ(fast.width, w);
        EXPECT_EQ(fast.height, h);
        EXPECT_EQ(fast.channels, c);
        EXPECT_EQ(fast.data, image.data) << path;
        EXPECT_EQ(fast.data, ReadWithOpenCv(path).data) << path;
      }
    }
  }
}

TEST(PngDecodeFast, LeavesOtherAndDamagedFilesToLibpng) {
  const std::string dir = ScratchDir();
  const std::string path = dir + "/rgb.png";
  WritePng(path, MixedImage(20, 10, 3));
  const std::string good = ReadFileBytes(path, "PNG file");
  ImageU8 out;
  // 16-bit: not this path's; ReadPng still refuses it with libpng's message.
  ImageU16 deep(4, 4, 1);
  WritePng16(dir + "/deep.png", deep);
  EXPECT_FALSE(DecodePngFast(ReadFileBytes(dir + "/deep.png", "PNG"), &out));
  EXPECT_THROW(ReadPng(dir + "/deep.png"), InputError);
  // A flipped bit in the image data (CRC mismatch) and a truncated file.
  std::string flipped = good;
  flipped[flipped.size() - 20] ^= 1;
  EXPECT_FALSE(DecodePngFast(flipped, &out));
  EXPECT_FALSE(DecodePngFast(good.substr(0, good.size() / 2), &out));
  const std::string broken = dir + "/broken.png";
  WriteFileAtomically(broken, flipped);
  EXPECT_THROW(ReadPng(broken), InputError);
  EXPECT_TRUE(out.empty());  // nothing written on failure
}

// Every truncation and many corrupted bytes of a small file: never a read out of
// bounds (the sanitizer run), and an image only when the damage missed the checks.
TEST(PngDecodeFast, SurvivesTruncationAndCorruption) {
  const ImageU8 image = MixedImage(9, 6, 3);
  const std::string good = PngWithEveryFilter(image);
  ImageU8 out;
  for (size_t n = 0; n < good.size(); ++n) {
    EXPECT_FALSE(DecodePngFast(good.substr(0, n), &out)) << n << " bytes";
  }
  std::mt19937_64& rng = TestRng();
  for (int trial = 0; trial < 2000; ++trial) {
    std::string bad = good;
    bad[8 + rng() % (bad.size() - 8)] ^= static_cast<char>(1 + rng() % 255);
    ImageU8 decoded;
    if (DecodePngFast(bad, &decoded)) {
      EXPECT_EQ(decoded.data.size(), size_t(decoded.width) * decoded.height * 3);
    }
  }
}

}  // namespace
}  // namespace handlabel
