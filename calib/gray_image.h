#pragma once
// An 8-bit grey image in row-major order, and PNG/JPEG I/O for it (OpenCV stays inside
// calib's .cc files).

#include <cstdint>
#include <string>
#include <vector>

namespace handlabel {

struct GrayImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // width * height, row-major

  GrayImage() = default;
  GrayImage(int w, int h, uint8_t value = 0)
      : width(w), height(h), pixels(size_t(w) * h, value) {}
  uint8_t& at(int x, int y) { return pixels[size_t(y) * width + x]; }
  uint8_t at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

// Any format OpenCV reads, converted to grey; throws InputError naming the file.
GrayImage ReadGrayImage(const std::string& path);
// Format from the extension (.png, .jpg); throws InputError if the write fails.
void WriteGrayImage(const GrayImage& image, const std::string& path);

}  // namespace handlabel
