#pragma once
// Image files by content: PNG (image/image.h, libpng) or JPEG (libjpeg), so that
// readers of dataset layouts that ship JPEGs (DexYCB's color_%06d.jpg) hand the same
// paths to every stage as the native PNG captures.

#include <string>

#include "image/image.h"

namespace handlabel {

struct JpegWriteOptions {
  // libjpeg quality 1-100.
  int quality = 95;
  // Full-resolution chroma (4:4:4) instead of libjpeg's default 4:2:0: larger files,
  // no colour bleeding at edges.
  bool full_chroma = true;
};

// A gray (1) or RGB (3) image as baseline JPEG file bytes.
std::string EncodeJpeg(const ImageU8& image, const JpegWriteOptions& options = {});

// Writes a gray (1) or RGB (3) baseline JPEG. Creates missing parent folders. Throws
// Error naming the path on failure.
void WriteJpeg(const std::string& path, const ImageU8& image,
               const JpegWriteOptions& options = {});

// Reads a JPEG as gray (1) or RGB (3) channels (CMYK/YCCK is rejected). Throws
// InputError naming the path when the file is missing, not a JPEG or corrupt.
ImageU8 ReadJpeg(const std::string& path);

// PNG or JPEG, told apart by the file's first bytes (not its name). Throws InputError
// naming the path for anything else.
ImageU8 ReadImageFile(const std::string& path);

}  // namespace handlabel
