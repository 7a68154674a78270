#include "capture/frame_images.h"

#include "image/view_image.h"

namespace handlabel {

void DecodeFrameImages(FrameInput* frame) {
  if (!frame->images.empty()) return;
  std::vector<ImageU8> images(frame->rig.size());
  for (size_t v = 0; v < images.size(); ++v) {
    if (v < frame->image_paths.size() && !frame->image_paths[v].empty()) {
      images[v] = ReadViewImageRgb(frame->image_paths[v], frame->rig[v]);
    }
  }
  frame->images = std::move(images);
}

ImageU8 FrameViewImageRgb(const FrameInput& frame, size_t v) {
  if (v < frame.images.size()) return frame.images[v];
  if (v < frame.image_paths.size() && v < frame.rig.size() &&
      !frame.image_paths[v].empty()) {
    return ReadViewImageRgb(frame.image_paths[v], frame.rig[v]);
  }
  return ImageU8();
}

}  // namespace handlabel
