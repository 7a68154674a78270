#pragma once
// A camera's empty scene from a recording of it: the per-pixel median over frames, each
// frame's pixels under a mask left out (where the hand was), so that a hand moving
// through the recording vanishes from the result even where it stays still for a
// while. Used to composite synthetic hands onto a capture's own backgrounds
// (docs/adapt.md).

#include <vector>

#include "image/image.h"

namespace handlabel {

// `images`: same size and channels, at least one. `left_out`: empty, or one 1-channel
// mask per image of the same size, nonzero = this image does not count at that pixel.
// Each channel of each pixel is the median (the lower middle value for an even count)
// of the images that count there; a pixel that every image leaves out takes the median
// of them all. Throws InputError naming the image index and what was expected for
// inconsistent sizes.
ImageU8 MedianImage(const std::vector<ImageU8>& images,
                    const std::vector<ImageU8>& left_out);

}  // namespace handlabel
