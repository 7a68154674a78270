#include "image/png_decode_fast.h"

#include <libdeflate.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "formats/big_endian.h"

namespace handlabel {
namespace {

// Channels of an IHDR this path decodes (8-bit gray, RGB or RGBA, deflate, standard
// filters, not interlaced); 0 for any other.
int FastChannels(const unsigned char* ihdr) {
  const int depth = ihdr[8], color = ihdr[9];
  if (depth != 8 || ihdr[10] != 0 || ihdr[11] != 0 || ihdr[12] != 0) return 0;
  return color == 0 ? 1 : color == 2 ? 3 : color == 6 ? 4 : 0;
}

int Paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return a;
  return pb <= pc ? b : c;
}

// Undoes one row's filter in place (PNG spec, section 9); `prev` is the unfiltered
// row above (zeros above the first). False for an unknown filter type.
bool Unfilter(int type, size_t bpp, const uint8_t* prev, uint8_t* row, size_t n) {
  switch (type) {
    case 0:
      return true;
    case 1:
      for (size_t i = bpp; i < n; ++i) row[i] += row[i - bpp];
      return true;
    case 2:
      for (size_t i = 0; i < n; ++i) row[i] += prev[i];
      return true;
    case 3:
      for (size_t i = 0; i < n; ++i) {
        const int left = i >= bpp ? row[i - bpp] : 0;
        row[i] += (left + prev[i]) >> 1;
      }
      return true;
    case 4:
      for (size_t i = 0; i < n; ++i) {
        const int left = i >= bpp ? row[i - bpp] : 0;
        const int up_left = i >= bpp ? prev[i - bpp] : 0;
        row[i] += Paeth(left, prev[i], up_left);
      }
      return true;
    default:
      return false;
  }
}

struct PngChunks {
  uint32_t width = 0, height = 0;
  int channels = 0;
  std::string idat;  // the IDAT chunks' data, joined
};

// Walks the chunks after the signature; false when the file is not for this path or
// is damaged (bounds, CRC, order).
bool ReadChunks(const std::string& bytes, PngChunks* png) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t size = bytes.size();
  bool header = false;
  for (size_t at = 8;;) {
    if (size < at + 12) return false;
    const uint32_t length = ReadBigEndian32(p + at);
    if (length > size - at - 12) return false;
    const unsigned char* type = p + at + 4;
    const unsigned char* data = type + 4;
    if (libdeflate_crc32(0, type, length + 4) != ReadBigEndian32(data + length))
      return false;
    at += 12 + static_cast<size_t>(length);
    if (std::memcmp(type, "IHDR", 4) == 0) {
      if (header || length != 13) return false;
      png->width = ReadBigEndian32(data);
      png->height = ReadBigEndian32(data + 4);
      png->channels = FastChannels(data);
      if (png->channels == 0 || png->width == 0 || png->height == 0) return false;
      header = true;
    } else if (!header || std::memcmp(type, "tRNS", 4) == 0) {
      return false;
    } else if (std::memcmp(type, "IDAT", 4) == 0) {
      png->idat.append(reinterpret_cast<const char*>(data), length);
    } else if (std::memcmp(type, "IEND", 4) == 0) {
      return true;
    } else if (!(type[0] & 0x20) && std::memcmp(type, "PLTE", 4) != 0) {
      return false;  // an unknown critical chunk
    }
  }
}

}  // namespace

bool DecodePngFast(const std::string& bytes, ImageU8* image) {
  PngChunks png;
  if (!ReadChunks(bytes, &png)) return false;
  // Larger images go to libpng, which names the limit (image/image.cc).
  if (double(png.width) * png.height * png.channels > 1e9) return false;
  const size_t stride = size_t(png.width) * png.channels;
  std::vector<uint8_t> raw(png.height * (stride + 1));
  const std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)>
      inflater(libdeflate_alloc_decompressor(), libdeflate_free_decompressor);
  if (!inflater) return false;
  size_t inflated = 0;
  if (libdeflate_zlib_decompress(inflater.get(), png.idat.data(), png.idat.size(),
                                 raw.data(), raw.size(),
                                 &inflated) != LIBDEFLATE_SUCCESS ||
      inflated != raw.size()) {
    return false;
  }
  ImageU8 out(static_cast<int>(png.width), static_cast<int>(png.height), png.channels);
  const std::vector<uint8_t> zeros(stride, 0);
  const uint8_t* prev = zeros.data();
  for (uint32_t y = 0; y < png.height; ++y) {
    uint8_t* row = raw.data() + y * (stride + 1);
    if (!Unfilter(row[0], png.channels, prev, row + 1, stride)) return false;
    std::memcpy(&out.at(0, static_cast<int>(y)), row + 1, stride);
    prev = row + 1;
  }
  *image = std::move(out);
  return true;
}

}  // namespace handlabel
