#pragma once
// Masks of a posed hand mesh seen by a camera (core/rasterizer.h) and their IoU with a
// silhouette mask: the per-view quality figure of a fit.

#include "core/hand_lbs.h"
#include "core/mask_image.h"
#include "core/rasterizer.h"
#include "core/rig.h"

namespace handlabel {

// Pixels covered by the mesh (world-frame vertices, the model's faces) in `camera`;
// `rays` must be PixelRays(camera.camera).
MaskImage RenderHandMask(const Points3d& vertices, const MeshFaces& faces,
                         const RigCamera& camera, const PixelRays& rays);

// |A and B| / |A or B| over nonzero pixels; 1 when both are empty.
// Pixels where `ignore` is set (occluded: neither mask can be judged there) do not
// count.
double MaskIoU(const MaskImage& a, const MaskImage& b, const MaskImage* ignore = nullptr);

}  // namespace handlabel
