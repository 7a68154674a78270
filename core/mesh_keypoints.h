#pragma once
// The 21 keypoints of a posed mesh read off its vertices alone: the model's joint
// regressor for the 16 joints, the tip vertices for the 5 fingertips (SNAP order). This
// is how keypoints are taken from a predicted mesh when no skeleton comes with it; on a
// posed hand it differs from the skinned joints (PoseHand's keypoints) because the
// regressor is fitted to rest meshes only.

#include "core/hand_lbs.h"  // Points3d, HandModel

namespace handlabel {

// vertices: model.num_vertices() x 3. Returns 21 x 3 in SNAP order.
Points3d KeypointsFromMeshVertices(const HandModel& model, const Points3d& vertices);

// The 21 SNAP keypoints from 16 joints (native order) and the mesh's tip vertices: the
// one place that knows how the two are interleaved (PoseHand uses it with the skinned
// joints).
Points3d SnapKeypoints(const HandModel& model, const Points3d& joints,
                       const Points3d& vertices);

}  // namespace handlabel
