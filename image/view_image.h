#pragma once
// A view's image or mask checked against its camera, so that a size mismatch names the
// file and the camera (the fitter and the detector know neither).

#include <string>

#include "geometry/rig.h"
#include "image/image.h"

namespace handlabel {

// Throws InputError naming `path`, the camera and both sizes when width x height is not
// the camera's image size.
void CheckViewImageSize(const std::string& path, int width, int height,
                        const RigCamera& camera);

// The image file (PNG or JPEG) as 3-channel RGB, grey replicated and alpha dropped;
// throws as CheckViewImageSize.
ImageU8 ReadViewImageRgb(const std::string& path, const RigCamera& camera);

}  // namespace handlabel
