#pragma once
// A separable Gaussian blur of float images in either memory layout the project uses:
// interleaved (ImageU8's RGBRGB..., converted to floats) and channel-major planes (the
// networks' 3 x S x S crops). One implementation serves the synthetic camera blur
// (capture/synth_appearance.h) and the training crops' blur augmentation
// (training/view_augmentation.h).

#include <cstddef>

namespace handlabel {

// Where element (x, y, c) of a dense float image lives:
// data[x * x_stride + y * y_stride + c * channel_stride], width * height * channels
// elements in all.
struct FloatImageLayout {
  int width = 0;
  int height = 0;
  int channels = 0;
  size_t x_stride = 0;
  size_t y_stride = 0;
  size_t channel_stride = 0;
  static FloatImageLayout Interleaved(int width, int height, int channels);
  static FloatImageLayout Planar(int width, int height, int channels);
};

// Blurs in place with a Gaussian of `sigma` pixels (kernel radius max(1, ceil(2.5
// sigma)), normalised; edge pixels repeated), rows first, then columns. sigma <= 0
// leaves the image as it is.
void GaussianBlurInPlace(double sigma, const FloatImageLayout& layout, float* data);

}  // namespace handlabel
