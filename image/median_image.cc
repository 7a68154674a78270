#include "image/median_image.h"

#include <algorithm>
#include <string>

#include "core/errors.h"

namespace handlabel {
namespace {

void CheckSizes(const std::vector<ImageU8>& images,
                const std::vector<ImageU8>& left_out) {
  if (images.empty()) throw InputError("median image", "images", "at least one", "none");
  const ImageU8& first = images[0];
  const auto size = [](const ImageU8& im, int channels) {
    return std::to_string(im.width) + " x " + std::to_string(im.height) + " x " +
           std::to_string(channels);
  };
  for (size_t i = 0; i < images.size(); ++i) {
    if (images[i].width != first.width || images[i].height != first.height ||
        images[i].channels != first.channels) {
      throw InputError("median image", "images[" + std::to_string(i) + "]",
                       size(first, first.channels) + " as images[0]",
                       size(images[i], images[i].channels));
    }
  }
  if (left_out.empty()) return;
  if (left_out.size() != images.size()) {
    throw InputError("median image", "left_out",
                     "one mask per image (" + std::to_string(images.size()) + ")",
                     std::to_string(left_out.size()));
  }
  for (size_t i = 0; i < left_out.size(); ++i) {
    if (left_out[i].width != first.width || left_out[i].height != first.height ||
        left_out[i].channels != 1) {
      throw InputError("median image", "left_out[" + std::to_string(i) + "]",
                       size(first, 1), size(left_out[i], left_out[i].channels));
    }
  }
}

uint8_t LowerMedian(std::vector<uint8_t>* values) {
  const auto middle = values->begin() + (values->size() - 1) / 2;
  std::nth_element(values->begin(), middle, values->end());
  return *middle;
}

}  // namespace

ImageU8 MedianImage(const std::vector<ImageU8>& images,
                    const std::vector<ImageU8>& left_out) {
  CheckSizes(images, left_out);
  const ImageU8& first = images[0];
  ImageU8 out(first.width, first.height, first.channels);
  const size_t pixels = static_cast<size_t>(first.width) * first.height;
  std::vector<uint8_t> values;
  values.reserve(images.size());
  for (size_t p = 0; p < pixels; ++p) {
    bool any_counts = left_out.empty();
    for (size_t i = 0; !any_counts && i < images.size(); ++i) {
      any_counts = left_out[i].data[p] == 0;
    }
    for (int c = 0; c < first.channels; ++c) {
      values.clear();
      for (size_t i = 0; i < images.size(); ++i) {
        if (any_counts && !left_out.empty() && left_out[i].data[p] != 0) continue;
        values.push_back(images[i].data[p * first.channels + c]);
      }
      out.data[p * first.channels + c] = LowerMedian(&values);
    }
  }
  return out;
}

}  // namespace handlabel
