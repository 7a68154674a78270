#include "image/image.h"

#include <png.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <type_traits>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "image/png_decode_fast.h"

namespace handlabel {
namespace {

void AppendToString(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  out->append(reinterpret_cast<const char*>(data), length);
}
void NoFlush(png_structp) {}

// Encodes rows of `bytes_per_row` bytes; libpng errors longjmp back here.
std::string Encode(int width, int height, int color_type, int bit_depth,
                   const std::vector<const uint8_t*>& rows, int level) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  HL_CHECK(png != nullptr, "png_create_write_struct");
  png_infop info = png_create_info_struct(png);
  std::string out;
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error("PNG encoding failed");
  }
  png_set_write_fn(png, &out, AppendToString, NoFlush);
  png_set_compression_level(png, level);
  // Sub filter only: much faster than adaptive filtering, nearly as small.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, width, height, bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (bit_depth == 16) png_set_swap(png);  // memory is little-endian, PNG big-endian
  png_write_image(png, const_cast<png_bytepp>(rows.data()));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw Error("cannot write " + path);
}

int ColorType(int channels) {
  switch (channels) {
    case 1:
      return PNG_COLOR_TYPE_GRAY;
    case 3:
      return PNG_COLOR_TYPE_RGB;
    case 4:
      return PNG_COLOR_TYPE_RGBA;
    default:
      HL_CHECK(false,
               "PNG images have 1, 3 or 4 channels, not " + std::to_string(channels));
  }
  return 0;
}

struct MemoryReader {
  const std::string* bytes;
  size_t offset = 0;
};
void ReadFromString(png_structp png, png_bytep data, png_size_t length) {
  auto* r = static_cast<MemoryReader*>(png_get_io_ptr(png));
  if (r->offset + length > r->bytes->size()) png_error(png, "truncated file");
  std::memcpy(data, r->bytes->data() + r->offset, length);
  r->offset += length;
}

// Decodes into 8-bit (want16 = false) or 16-bit gray (want16 = true).
template <typename T>
Image<T> Decode(const std::string& path, bool want16) {
  const std::string bytes = ReadFileBytes(path, "PNG file");
  if (bytes.size() < 8 ||
      png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0) {
    throw InputError(path, "signature", "a PNG file", "other data");
  }
  if constexpr (std::is_same_v<T, uint8_t>) {
    ImageU8 fast;
    if (!want16 && DecodePngFast(bytes, &fast)) return fast;
  }
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  HL_CHECK(png != nullptr, "png_create_read_struct");
  png_infop info = png_create_info_struct(png);
  Image<T> image;
  std::vector<png_bytep> rows;  // before setjmp: longjmp must not skip destructors
  // Messages cannot cross longjmp safely as std::string; keep a fixed buffer.
  static thread_local char problem[128];
  problem[0] = '\0';
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw InputError(path, "data", problem[0] ? problem : "a valid PNG", "corrupt data");
  }
  MemoryReader reader{&bytes, 0};
  png_set_read_fn(png, &reader, ReadFromString);
  png_read_info(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  const int color_type = png_get_color_type(png, info);
  if (want16) {
    if (bit_depth != 16 || color_type != PNG_COLOR_TYPE_GRAY) {
      std::snprintf(problem, sizeof(problem), "a 16-bit gray PNG");
      png_error(png, "wrong kind");
    }
    png_set_swap(png);
  } else {
    if (bit_depth == 16) {
      std::snprintf(problem, sizeof(problem), "an 8-bit PNG (this one is 16-bit)");
      png_error(png, "wrong kind");
    }
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8)
      png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  }
  png_read_update_info(png, info);
  const int width = png_get_image_width(png, info);
  const int height = png_get_image_height(png, info);
  const int channels = png_get_channels(png, info);
  if (static_cast<double>(width) * height * channels > 1e9) {
    std::snprintf(problem, sizeof(problem), "an image below 1e9 samples");
    png_error(png, "too large");
  }
  image = Image<T>(width, height, channels);
  rows.resize(height);
  for (int y = 0; y < height; ++y) {
    rows[y] = reinterpret_cast<png_bytep>(&image.at(0, y));
  }
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

}  // namespace

std::string EncodePng(const ImageU8& image, const PngWriteOptions& options) {
  HL_CHECK(!image.empty(), "empty image");
  std::vector<const uint8_t*> rows(image.height);
  for (int y = 0; y < image.height; ++y) rows[y] = &image.at(0, y);
  return Encode(image.width, image.height, ColorType(image.channels), 8, rows,
                options.compression_level);
}

void WritePng(const std::string& path, const ImageU8& image,
              const PngWriteOptions& options) {
  WriteBytes(path, EncodePng(image, options));
}

void WritePng16(const std::string& path, const ImageU16& image,
                const PngWriteOptions& options) {
  HL_CHECK(!image.empty() && image.channels == 1, "16-bit PNGs are gray");
  std::vector<const uint8_t*> rows(image.height);
  for (int y = 0; y < image.height; ++y) {
    rows[y] = reinterpret_cast<const uint8_t*>(&image.at(0, y));
  }
  WriteBytes(path, Encode(image.width, image.height, PNG_COLOR_TYPE_GRAY, 16, rows,
                          options.compression_level));
}

ImageU8 ReadPng(const std::string& path) { return Decode<uint8_t>(path, false); }
ImageU16 ReadPng16(const std::string& path) { return Decode<uint16_t>(path, true); }

}  // namespace handlabel
