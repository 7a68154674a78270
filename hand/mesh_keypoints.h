#pragma once
// The 21 keypoints of a posed mesh read off its vertices alone: the model's joint
// regressor for the 16 joints, the tip vertices for the 5 fingertips (SNAP order). This
// is how keypoints are taken from a predicted mesh when no skeleton comes with it; on a
// posed hand it differs from the skinned joints (PoseHand's keypoints) because the
// regressor is fitted to rest meshes only.

#include <optional>
#include <string>

#include "hand/hand_lbs.h"  // Points3d, HandModel

namespace handlabel {

// vertices: model.num_vertices() x 3. Returns 21 x 3 in SNAP order.
Points3d KeypointsFromMeshVertices(const HandModel& model, const Points3d& vertices);

// The 21 SNAP keypoints from 16 joints (native order) and the mesh's tip vertices: the
// one place that knows how the two are interleaved (PoseHand uses it with the skinned
// joints).
Points3d SnapKeypoints(const HandModel& model, const Points3d& joints,
                       const Points3d& vertices);

// How the 21 keypoints of a network's answer that carries both are read: its own joint
// outputs, the keypoints read off its mesh, or the mean of the two (two estimates whose
// errors are partly independent; docs/network.md "Keypoints of the answer" has the
// measurements that made kMean the default).
enum class AnswerKeypoints { kJoints, kMesh, kMean };

// joints: 21 x 3 (SNAP order); vertices: model.num_vertices() x 3, in the same frame.
Points3d ReadAnswerKeypoints(const HandModel& model, const Points3d& joints,
                             const Points3d& vertices, AnswerKeypoints how);

std::string ToString(AnswerKeypoints how);  // "joints" | "mesh" | "mean"
std::optional<AnswerKeypoints> AnswerKeypointsNamed(const std::string& name);
std::string AnswerKeypointsChoices();  // "joints | mesh | mean", for messages

}  // namespace handlabel
