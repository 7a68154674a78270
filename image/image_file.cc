#include "image/image_file.h"

// clang-format off
#include <cstdio>   // jpeglib.h needs FILE and size_t first
#include <jpeglib.h>
// clang-format on

#include <csetjmp>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/file_bytes.h"

namespace handlabel {
namespace {

// libjpeg reports fatal errors through error_exit, which must not return: jump back
// to the caller with the library's message kept in a fixed buffer (a std::string
// would be skipped by longjmp).
struct JpegError {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void ExitWithMessage(j_common_ptr info) {
  auto* error = reinterpret_cast<JpegError*>(info->err);
  info->err->format_message(info, error->message);
  std::longjmp(error->jump, 1);
}

// A warning means corrupt data that libjpeg would paper over (e.g. a truncated file
// decoded with a gray bottom): a label must not be made from it, so it is an error.
void FailOnWarning(j_common_ptr info, int level) {
  if (level < 0) info->err->error_exit(info);
}

// The whole file, or its first `max_bytes`.
std::string ReadBytes(const std::string& path, const std::string& what,
                      size_t max_bytes = std::string::npos) {
  if (max_bytes == std::string::npos) return ReadFileBytes(path, what);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "file", "an existing readable " + what, "missing");
  std::string head(max_bytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(max_bytes));
  head.resize(static_cast<size_t>(in.gcount()));
  return head;
}

bool IsJpeg(const std::string& bytes) {
  return bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xFF &&
         static_cast<unsigned char>(bytes[1]) == 0xD8 &&
         static_cast<unsigned char>(bytes[2]) == 0xFF;
}

bool IsPng(const std::string& bytes) {
  return bytes.size() >= 8 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
}

ImageU8 DecodeJpeg(const std::string& path, const std::string& bytes) {
  if (!IsJpeg(bytes)) throw InputError(path, "signature", "a JPEG file", "other data");
  jpeg_decompress_struct info;
  JpegError error;
  info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = ExitWithMessage;
  error.manager.emit_message = FailOnWarning;
  error.message[0] = '\0';
  ImageU8 image;  // before setjmp: longjmp must not skip destructors
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    throw InputError(path, "data", "a valid JPEG", error.message);
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(bytes.data()),
               static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&info, TRUE);
  if (info.jpeg_color_space == JCS_CMYK || info.jpeg_color_space == JCS_YCCK) {
    jpeg_destroy_decompress(&info);
    throw InputError(path, "colour space", "a gray or RGB JPEG", "CMYK");
  }
  info.out_color_space = info.num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(&info);
  image = ImageU8(static_cast<int>(info.output_width),
                  static_cast<int>(info.output_height), info.output_components);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = image.data.data() + image.index(0, info.output_scanline);
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return image;
}

}  // namespace

std::string EncodeJpeg(const ImageU8& image, const JpegWriteOptions& options) {
  HL_CHECK(image.channels == 1 || image.channels == 3, "gray or RGB image");
  HL_CHECK(options.quality >= 1 && options.quality <= 100, "quality in 1..100");
  jpeg_compress_struct info;
  JpegError error;
  info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = ExitWithMessage;
  error.message[0] = '\0';
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  if (setjmp(error.jump)) {
    jpeg_destroy_compress(&info);
    std::free(buffer);
    throw Error(std::string("JPEG encoding failed: ") + error.message);
  }
  jpeg_create_compress(&info);
  jpeg_mem_dest(&info, &buffer, &size);
  info.image_width = static_cast<JDIMENSION>(image.width);
  info.image_height = static_cast<JDIMENSION>(image.height);
  info.input_components = image.channels;
  info.in_color_space = image.channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, options.quality, TRUE);
  if (options.full_chroma && image.channels == 3) {
    for (int c = 0; c < 3; ++c) {
      info.comp_info[c].h_samp_factor = 1;
      info.comp_info[c].v_samp_factor = 1;
    }
  }
  jpeg_start_compress(&info, TRUE);
  while (info.next_scanline < info.image_height) {
    // libjpeg takes non-const rows but does not write to them.
    JSAMPROW row = const_cast<unsigned char*>(image.data.data()) +
                   image.index(0, static_cast<int>(info.next_scanline));
    jpeg_write_scanlines(&info, &row, 1);
  }
  jpeg_finish_compress(&info);
  jpeg_destroy_compress(&info);
  const std::string bytes(reinterpret_cast<const char*>(buffer), size);
  std::free(buffer);
  return bytes;
}

void WriteJpeg(const std::string& path, const ImageU8& image,
               const JpegWriteOptions& options) {
  const std::string bytes = EncodeJpeg(image, options);
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw Error("cannot write " + path);
}

ImageU8 ReadJpeg(const std::string& path) {
  return DecodeJpeg(path, ReadBytes(path, "JPEG file"));
}

ImageU8 ReadImageFile(const std::string& path) {
  const std::string head = ReadBytes(path, "PNG or JPEG file", 8);
  if (IsJpeg(head)) return ReadJpeg(path);
  if (IsPng(head)) return ReadPng(path);
  throw InputError(path, "signature", "a PNG or JPEG file", "other data");
}

}  // namespace handlabel
