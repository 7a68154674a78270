#pragma once
// Exact Euclidean distance transform of binary masks (Felzenszwalb & Huttenlocher's
// separable lower-envelope algorithm, O(pixels)), used by the silhouette terms of
// fitting. Images are row-major Eigen matrices: rows = height, (row, col) = (v, u),
// pixel centres at integer coordinates.

#include <Eigen/Core>

#include "image/mask_image.h"

namespace handlabel {

using DistanceImage =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Distance in pixels from each pixel centre to the nearest pixel centre whose mask value
// is nonzero (0 on the mask). If the mask is empty every entry is +infinity.
DistanceImage DistanceToMask(const MaskImage& mask);

// Distance to the mask's outside (nearest zero pixel); 0 outside the mask.
DistanceImage DistanceToOutside(const MaskImage& mask);

// A rectangle of pixels: columns x0 .. x0 + width - 1, rows y0 .. y0 + height - 1.
struct PixelWindow {
  int x0 = 0;
  int y0 = 0;
  int width = 0;
  int height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
};

// DistanceToMask over a window of the image only (height x width, entry (0, 0) is pixel
// (x0, y0)): the distance to the nearest pixel inside the window that is nonzero in
// `mask` or, if given, in `also` (same size). Exact where the nearest such pixel of the
// whole image lies in the window, which holds wherever the result is below the
// distance to the window's edge; all +infinity without such a pixel. The window must
// lie inside the image. Costs the window's area instead of the image's.
DistanceImage DistanceToMaskInWindow(const MaskImage& mask, const PixelWindow& window,
                                     const MaskImage* also = nullptr);

}  // namespace handlabel
