#pragma once
// Images in memory (row-major, interleaved channels) and PNG files through libpng.
// Pixel (x, y) channel c lives at data[(y * width + x) * channels + c]; the centre of
// the top-left pixel is (0, 0), as everywhere in handlabel.
//
//   ImageU8   8-bit RGB (3 channels), gray/masks (1) or RGBA (4)   <-> 8-bit PNG
//   ImageU16  16-bit gray, e.g. depth in fixed units               <-> 16-bit PNG
//   ImageF    float, e.g. depth in metres (in memory only)

#include <cstdint>
#include <string>
#include <vector>

namespace handlabel {

template <typename T>
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<T> data;

  Image() = default;
  Image(int w, int h, int c, T fill = T(0))
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}

  bool empty() const { return data.empty(); }
  size_t index(int x, int y, int c = 0) const {
    return (static_cast<size_t>(y) * width + x) * channels + c;
  }
  T& at(int x, int y, int c = 0) { return data[index(x, y, c)]; }
  const T& at(int x, int y, int c = 0) const { return data[index(x, y, c)]; }
  bool Contains(int x, int y) const {
    return x >= 0 && y >= 0 && x < width && y < height;
  }
  void Fill(T value) { std::fill(data.begin(), data.end(), value); }
};

using ImageU8 = Image<uint8_t>;
using ImageU16 = Image<uint16_t>;
using ImageF = Image<float>;

struct PngWriteOptions {
  // zlib level 0-9: 1 is several times faster than the default 6 and only ~15 % larger
  // on rendered images. Output bytes depend only on pixels and this level.
  int compression_level = 1;
};

// Writes 1 (gray), 3 (RGB) or 4 (RGBA) channels. Creates missing parent folders.
// Throws Error naming the path on failure.
void WritePng(const std::string& path, const ImageU8& image,
              const PngWriteOptions& options = {});
// 16-bit gray PNG (big-endian on disk as PNG requires).
void WritePng16(const std::string& path, const ImageU16& image,
                const PngWriteOptions& options = {});

// PNG bytes in memory (same encoding as WritePng).
std::string EncodePng(const ImageU8& image, const PngWriteOptions& options = {});

// Reads an 8-bit PNG as gray (1), RGB (3) or RGBA (4) channels, as stored (palette
// images are expanded to RGB, gray+alpha to RGBA). Throws InputError naming the path
// when the file is missing, not a PNG or 16-bit.
ImageU8 ReadPng(const std::string& path);
// Reads a 16-bit gray PNG (e.g. depth). Throws InputError if it is not one.
ImageU16 ReadPng16(const std::string& path);

}  // namespace handlabel
