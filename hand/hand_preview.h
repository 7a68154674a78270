#pragma once
// Preview pictures of a hand model: a sheet with one row per named pose and one column
// per view (palm, back, thumb side), rendered by the software rasteriser in
// mesh_render.h. Optionally coloured by skinning weights.

#include <string>
#include <vector>

#include "hand/hand_lbs.h"
#include "hand/hand_model.h"
#include "image/mesh_render.h"

namespace handlabel {

struct NamedHandPose {
  std::string name;
  HandParams params;
};

// rest, fist, pinch, point, spread, grasp: built from anatomical angles, so they work
// for any MANO-structured model of either side.
std::vector<NamedHandPose> PreviewHandPoses(const HandModel& model);

enum class HandPreviewColoring { kSkin, kSkinningWeights };

struct HandPreviewOptions {
  int tile_size = 256;  // pixels per tile (square)
  HandPreviewColoring coloring = HandPreviewColoring::kSkin;
  // Views (columns): "palm", "back", "thumb", "pinky", "tip".
  std::vector<std::string> views = {"palm", "back", "thumb"};
  void Check(const std::string& source) const;
};

// One row per pose; every tile uses the same scale so sizes compare.
ImageU8 RenderHandSheet(const HandModel& model, const std::vector<NamedHandPose>& poses,
                        const HandPreviewOptions& options);

// One colour per joint (16), for weight pictures.
Eigen::Vector3d JointColor(int joint);

}  // namespace handlabel
