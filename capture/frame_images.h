#pragma once
// A frame's view images, decoded once: a labeling job hands each frame to the network's
// crops, the detector and the overlay writer, and a PNG decode of a 640 x 480 view costs
// more than cropping it. The runner decodes in its parallel read stage; the stages take
// the decoded image, or read the file when the frame holds none.

#include <cstddef>

#include "capture/frame_source.h"
#include "image/image.h"

namespace handlabel {

// Fills frame->images (when empty) from frame->image_paths: RGB (grey replicated, alpha
// dropped), a 0 x 0 image for a view without a path. Throws InputError naming the file
// that cannot be read or whose size is not its camera's.
void DecodeFrameImages(FrameInput* frame);

// View v's image as RGB: the decoded one when the frame holds it, else read from its
// file (throws as DecodeFrameImages). A view without an image file (no path, or a 0 x 0
// decoded image) gives a 0 x 0 image.
ImageU8 FrameViewImageRgb(const FrameInput& frame, size_t v);

}  // namespace handlabel
