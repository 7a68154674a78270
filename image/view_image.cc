#include "image/view_image.h"

#include "core/errors.h"
#include "image/image_file.h"

namespace handlabel {

void CheckViewImageSize(const std::string& path, int width, int height,
                        const RigCamera& camera) {
  const int w = camera.camera.width(), h = camera.camera.height();
  if (width != w || height != h) {
    throw InputError(
        path, "image size",
        std::to_string(w) + "x" + std::to_string(h) + " (camera " + camera.name + ")",
        std::to_string(width) + "x" + std::to_string(height));
  }
}

ImageU8 ReadViewImageRgb(const std::string& path, const RigCamera& camera) {
  const ImageU8 image = ReadImageFile(path);
  CheckViewImageSize(path, image.width, image.height, camera);
  if (image.channels == 3) return image;
  ImageU8 rgb(image.width, image.height, 3, 0);
  for (size_t p = 0; p < size_t(image.width) * image.height; ++p) {
    for (int c = 0; c < 3; ++c) {
      rgb.data[3 * p + c] = image.data[p * image.channels + (image.channels < 3 ? 0 : c)];
    }
  }
  return rgb;
}

}  // namespace handlabel
