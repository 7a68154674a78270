#pragma once
// The fast path of ReadPng for the PNGs captures are made of: 8-bit gray, RGB or RGBA,
// not interlaced, without tRNS. Chunk CRCs are checked, the image data is inflated in
// one call with libdeflate (zlib's streaming inflate and libpng were ~14 % of a label
// job's CPU, docs/speed.md) and unfiltered here. Any other PNG, and any damage, returns
// false: libpng then decodes the file or reports what is wrong with it.

#include <string>

#include "image/image.h"

namespace handlabel {

// `bytes`: a whole PNG file whose 8-byte signature the caller has checked.
bool DecodePngFast(const std::string& bytes, ImageU8* image);

}  // namespace handlabel
