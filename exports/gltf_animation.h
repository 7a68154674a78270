#pragma once
// A label series as one animated, skinned hand in binary glTF 2.0 (.glb), for Blender,
// game engines and viewers (docs/exports.md, "--format glb"):
//   - the hand model's mesh (shaped with the first label's betas: the bind pose) with
//     its 16 joints as a node hierarchy (names as hand_anatomy.h's JointName) and a
//     skin of up to 4 joints per vertex (the model's largest weights, renormalised);
//   - one animation "labels", one keyframe per label at frame k / fps: each joint's
//     rotation (the label's axis-angle as a quaternion) and translation (the label's
//     rest joints, so a joint node sits on the label's joint; the root adds transl),
//     LINEAR; and one morph target per label, switched on at its keyframe (STEP), that
//     makes the skinned mesh exactly the label's vertices there (it carries what glTF's
//     skinning cannot: MANO's pose blend shapes, shape changes, the dropped weights).
// Coordinates are the labels' (metres, the rig's world frame), not turned to glTF's
// +Y up: the root node is the identity. Every label needs MANO parameters.

#include <string>

#include "exports/label_series.h"
#include "hand/hand_model.h"

namespace handlabel {

struct GltfAnimationOptions {
  double fps = 30;  // keyframes per second (the capture's frame rate)
  // Throws InputError naming `source` when fps is not positive.
  void Check(const std::string& source) const;
};

// The .glb bytes. Throws InputError naming the label file of a frame without MANO
// parameters or with another vertex count than `model`.
std::string HandAnimationGlb(const LabelSeries& series, const HandModel& model,
                             const GltfAnimationOptions& options);

}  // namespace handlabel
