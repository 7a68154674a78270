#pragma once
// Skinning weights of the open hand, from the skeleton: every vertex belongs to the
// nearest of the five chains (thumb, index, middle, ring, pinky); along that chain its
// weights blend smoothly across each joint over a zone proportional to the local finger
// radius (smoothstep of the distance past the joint plane), and the first joint of a
// chain fades out with distance from the bone axis so the palm stays with the wrist.
// A few rounds of mesh Laplacian smoothing remove the seams where the nearest chain
// changes (between fingers). Rows sum to 1.

#include <Eigen/Core>

#include "openhand/design.h"
#include "openhand/implicit_mesher.h"

namespace handlabel {

using SkinningWeights =
    Eigen::Matrix<double, Eigen::Dynamic, kNumHandJoints, Eigen::RowMajor>;

struct OpenHandSkinningOptions {
  double finger_blend = 0.9;     // half width of a finger joint's blend zone / radius
  double thumb_cmc_blend = 1.2;  // same for the thumb CMC (the thenar is soft)
  int smoothing_rounds = 4;      // Laplacian smoothing rounds over the mesh
  double min_weight = 1e-4;      // smaller weights are dropped (rows renormalised)
  void Check(const std::string& source) const;
};

SkinningWeights OpenHandSkinningWeights(const TriangleMesh& mesh,
                                        const OpenHandSkeleton& skeleton,
                                        const OpenHandSkinningOptions& options);

// The chains as native joint ids: chain 0 thumb (13, 14, 15), then index, middle, ring,
// pinky; chain c ends at tip c of the skeleton.
std::array<std::array<int, 3>, 5> OpenHandChains();

}  // namespace handlabel
