#pragma once
// Conversion between a COLMAP model and a Rig: every COLMAP image is one rig camera.
//
// Camera names: the image name without an image extension (.png .jpg .jpeg .bmp .tif
// .tiff); when every image lies in a folder ("cam0/000000.png") and the folders are
// all different, the folder name ("cam0") — the layout of one camera per folder.
// ColmapFromRig writes camera i as camera id i+1 and image id i+1 named after the rig
// camera, so a rig whose names hold no '/' survives the round trip unchanged.

#include <string>

#include "cameras/colmap_model.h"
#include "geometry/rig.h"

namespace handlabel {

// Throws InputError naming `source` for unusable models (no images, duplicate names,
// image sizes beyond int).
Rig RigFromColmap(const ColmapModel& model, const std::string& source);
ColmapModel ColmapFromRig(const Rig& rig);

// The rig camera name for one COLMAP image name (without the folder rule).
std::string CameraNameFromImageName(const std::string& image_name);

}  // namespace handlabel
