#pragma once
// Masks of a posed hand mesh seen by a camera (image/rasterizer.h) and their IoU with a
// silhouette mask: the per-view quality figure of a fit.

#include "geometry/rig.h"
#include "hand/hand_lbs.h"
#include "image/mask_image.h"
#include "image/rasterizer.h"

namespace handlabel {

// Pixels covered by the mesh (world-frame vertices, the model's faces) in `camera`;
// `rays` must be PixelRays(camera.camera).
MaskImage RenderHandMask(const Points3d& vertices, const Faces& faces,
                         const RigCamera& camera, const PixelRays& rays);

// The IoU (as MaskIoU) of `mask` and the pixels the mesh covers in `camera`, without a
// whole-image rendering: each face's projected triangle (vertices projected with lens
// distortion, straight edges) is filled in a window around the projected mesh (pixel
// centres inside or on an edge; faces with a vertex behind the camera are skipped).
// Straight edges between distorted vertices stay within ~1e-3 px of RenderHandMask's
// curved ones for a hand's faces of a few pixels.
double ProjectedMeshIoU(const Points3d& vertices, const Faces& faces,
                        const RigCamera& camera, const MaskImage& mask,
                        const MaskImage* ignore = nullptr);

// |A and B| / |A or B| over nonzero pixels; 1 when both are empty.
// Pixels where `ignore` is set (occluded: neither mask can be judged there) do not
// count.
double MaskIoU(const MaskImage& a, const MaskImage& b, const MaskImage* ignore = nullptr);

}  // namespace handlabel
