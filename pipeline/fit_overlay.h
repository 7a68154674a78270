#pragma once
// A picture of one fitted frame: every view in a grid (square tiles cropped around
// the fitted hand) with the fitted mesh's silhouette
// tinted green over the image, the fitted keypoints and skeleton (green) and the 2D
// evidence the fit used (red crosses), for checking a fit at a glance.

#include "core/hand_lbs.h"
#include "core/image.h"
#include "core/rasterizer.h"
#include "fitting/keypoint_view.h"

namespace handlabel {

struct FitOverlayOptions {
  int columns = 4;       // views per row (>= 1)
  int tile_width = 240;  // side of each square tile in pixels (>= 16)
};

// `images[v]` is view v's RGB image, `rays[v]` its PixelRays; `vertices` / `keypoints`
// the fitted hand in world coordinates; `faces` the model's.
ImageU8 MakeFitOverlay(const std::vector<ImageU8>& images,
                       const std::vector<KeypointView>& views,
                       const std::vector<PixelRays>& rays, const Points3d& vertices,
                       const MeshFaces& faces, const Points3d& keypoints,
                       const FitOverlayOptions& options = {});

}  // namespace handlabel
