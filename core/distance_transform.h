#pragma once
// Exact Euclidean distance transform of binary masks (Felzenszwalb & Huttenlocher's
// separable lower-envelope algorithm, O(pixels)), used by the silhouette terms of
// fitting. Images are row-major Eigen matrices: rows = height, (row, col) = (v, u),
// pixel centres at integer coordinates.

#include <Eigen/Core>

#include "core/mask_image.h"

namespace handlabel {

using DistanceImage =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Distance in pixels from each pixel centre to the nearest pixel centre whose mask value
// is nonzero (0 on the mask). If the mask is empty every entry is +infinity.
DistanceImage DistanceToMask(const MaskImage& mask);

// Distance to the mask's outside (nearest zero pixel); 0 outside the mask.
DistanceImage DistanceToOutside(const MaskImage& mask);

}  // namespace handlabel
