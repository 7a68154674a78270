#pragma once
// Shape space of the open hand: random designs around the default (anthropometric
// variation, open_hand_design.h) are carried onto the default mesh by a skinning-like
// blend of per-bone similarity maps (each bone moves, turns and stretches to its new
// length and girth; the palm follows an affine map of its joints), and the offsets of
// vertices and joints from the default are reduced by PCA (about the default, so
// betas = 0 is the designed hand). Components are ordered by variance and scaled by
// their standard deviation, so betas are ~N(0, 1) as in MANO.

#include <Eigen/Core>
#include <random>

#include "openhand/design.h"
#include "openhand/implicit_mesher.h"
#include "openhand/skinning.h"

namespace handlabel {

// The default mesh deformed to `target` (same vertex order).
std::vector<Eigen::Vector3d> DeformToDesign(const std::vector<Eigen::Vector3d>& vertices,
                                            const SkinningWeights& weights,
                                            const OpenHandDesign& from,
                                            const OpenHandDesign& target);

struct OpenHandShapeSpace {
  Eigen::MatrixXd vertex_dirs;  // 3V x K (row 3v + c), MANO shapedirs layout
  Eigen::MatrixXd joint_dirs;   // 48 x K (row 3j + c)
  Eigen::VectorXd stddev;       // K: standard deviation (metres, RMS over the vector)
  double explained = 0.0;       // fraction of the sample variance the K components hold
};

OpenHandShapeSpace BuildOpenHandShapeSpace(const std::vector<Eigen::Vector3d>& vertices,
                                           const SkinningWeights& weights,
                                           const OpenHandDesign& design,
                                           const OpenHandVariation& variation,
                                           int num_components, int num_samples,
                                           std::mt19937_64& rng);

}  // namespace handlabel
