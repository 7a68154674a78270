#include "image/mask_image.h"

namespace handlabel {

MaskImage MaskFromImage(const ImageU8& image) {
  MaskImage mask(image.height, image.width);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) mask(y, x) = image.at(x, y, 0) > 127 ? 255 : 0;
  }
  return mask;
}

MaskImage ReadMaskPng(const std::string& path) { return MaskFromImage(ReadPng(path)); }

MaskImage ReadObjectMaskPng(const std::string& path) {
  const ImageU8 image = ReadPng(path);
  MaskImage mask(image.height, image.width);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) mask(y, x) = image.at(x, y, 0) != 0 ? 255 : 0;
  }
  return mask;
}

}  // namespace handlabel
