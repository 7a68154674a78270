#pragma once
// Builds the project's open hand model (a MANO-compatible HandModel) from a design:
//   1. implicit surface of the design (open_hand_design.h), meshed by marching
//      tetrahedra on a fine grid, decimated with OpenMesh to ~MANO's resolution, edges
//      flipped towards Delaunay, and relaxed onto the surface for even triangles;
//   2. skinning weights from the skeleton (open_hand_skinning.h);
//   3. a 10-component shape space by PCA of sampled designs (open_hand_shape_space.h);
//   4. a sparse joint regressor: each joint is a convex combination of the vertices
//      around it, fitted by NNLS so that it reproduces the design joints for the mean
//      shape and along every shape direction;
//   5. fingertip vertex ids (nearest vertex to each designed fingertip);
//   6. a pose PCA basis and mean from natural poses (hand/hand_pose_sampler.h);
//   7. pose blend shapes are zero (plain LBS; documented in docs/open-hand.md).
// The left hand is the exact mirror (MirrorHandModel). Same options -> same model,
// bit for bit.

#include <cstdint>
#include <string>

#include "hand/hand_model.h"
#include "openhand/design.h"
#include "openhand/mesh_decimation.h"
#include "openhand/skinning.h"

namespace handlabel {

struct OpenHandBuildOptions {
  HandSide side = HandSide::kRight;
  uint64_t seed = 1;              // shape and pose sampling
  double grid_step = 0.0012;      // marching-tetrahedra grid spacing (metres)
  int target_vertices = 778;      // after decimation (MANO: 778)
  int relax_iterations = 8;       // tangential relaxation rounds after decimation
  int num_betas = 10;             // shape components
  int num_shape_samples = 200;    // sampled designs for the shape PCA
  int num_pose_samples = 4000;    // sampled natural poses for the pose PCA
  double regressor_radius = 2.5;  // regressor support: vertices within this many
                                  // local radii of the joint (axial offsets count 3x)
  OpenHandVariation variation;
  OpenHandSkinningOptions skinning;
  void Check(const std::string& source) const;
};

// Diagnostics of one build.
struct OpenHandBuildReport {
  int fine_vertices = 0, fine_faces = 0;  // marching-tetrahedra mesh
  double shape_variance_explained = 0.0;
  double max_regressor_error = 0.0;        // metres, over mean + shape directions
  double max_regressor_error_mean = 0.0;   // metres, mean shape only
  double pose_variance_explained_6 = 0.0;  // pose PCA: first 6 components
};

HandModel BuildOpenHand(const OpenHandDesign& design, const OpenHandBuildOptions& options,
                        OpenHandBuildReport* report = nullptr);

// The mirror image (x -> -x) of a model: faces turned to stay counter-clockwise, shape
// and pose blend shapes mirrored, pose PCA mirrored (axis-angle (x, y, z) ->
// (x, -y, -z)), side flipped, name "..._right" -> "..._left".
HandModel MirrorHandModel(const HandModel& model);

}  // namespace handlabel
