#pragma once
// The one mask-image type of the project and the one rule for turning a mask picture
// into a silhouette. A MaskImage is row-major (rows = image height, (row, col) = (v, u));
// a nonzero pixel is hand. Masks read from files and the network's hold 255 for hand.
//
// Mask rule: a pixel of a mask picture is hand when its first channel is > 127. Mask
// PNGs written by handlabel are 0/255; the threshold keeps anti-aliased or resampled
// masks from other tools (values 1..127 at the border) from growing the silhouette.

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "image/image.h"

namespace handlabel {

using MaskImage = Eigen::Matrix<uint8_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Applies the mask rule to an image in memory (the first channel): 255 = hand, 0 = not.
MaskImage MaskFromImage(const ImageU8& image);

// Reads a mask PNG and applies the mask rule. Throws InputError naming the path when
// the file is missing or not an 8-bit PNG.
MaskImage ReadMaskPng(const std::string& path);
// An object label map (0 = no object, k = object k; capture/capture_format.h
// object_masks) as a mask: any non-zero pixel is an object (255).
MaskImage ReadObjectMaskPng(const std::string& path);

}  // namespace handlabel
