#include "hand/mesh_keypoints.h"

#include <string>

#include "core/errors.h"

namespace handlabel {

Points3d KeypointsFromMeshVertices(const HandModel& model, const Points3d& vertices) {
  if (vertices.rows() != model.num_vertices()) {
    throw InputError("mesh", "vertices", std::to_string(model.num_vertices()) + " rows",
                     std::to_string(vertices.rows()));
  }
  return SnapKeypoints(model, model.joint_regressor * vertices, vertices);
}

Points3d SnapKeypoints(const HandModel& model, const Points3d& joints,
                       const Points3d& vertices) {
  HL_CHECK(joints.rows() == kNumHandJoints, "16 joints");
  Points3d keypoints(kNumHandKeypoints, 3);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int native = kSnapFromNative[k];
    keypoints.row(k) = native < kNumHandJoints
                           ? joints.row(native)
                           : vertices.row(model.tip_vertex_ids[native - kNumHandJoints]);
  }
  return keypoints;
}

Points3d ReadAnswerKeypoints(const HandModel& model, const Points3d& joints,
                             const Points3d& vertices, AnswerKeypoints how) {
  if (how == AnswerKeypoints::kJoints) return joints;
  const Points3d from_mesh = KeypointsFromMeshVertices(model, vertices);
  if (how == AnswerKeypoints::kMesh) return from_mesh;
  HL_CHECK(joints.rows() == kNumHandKeypoints, "21 keypoints");
  return 0.5 * (joints + from_mesh);
}

std::string ToString(AnswerKeypoints how) {
  switch (how) {
    case AnswerKeypoints::kJoints:
      return "joints";
    case AnswerKeypoints::kMesh:
      return "mesh";
    case AnswerKeypoints::kMean:
      return "mean";
  }
  return "?";
}

namespace {
constexpr AnswerKeypoints kAllReadings[] = {
    AnswerKeypoints::kJoints, AnswerKeypoints::kMesh, AnswerKeypoints::kMean};
}  // namespace

std::optional<AnswerKeypoints> AnswerKeypointsNamed(const std::string& name) {
  for (AnswerKeypoints how : kAllReadings) {
    if (ToString(how) == name) return how;
  }
  return std::nullopt;
}

std::string AnswerKeypointsChoices() {
  std::string out;
  for (AnswerKeypoints how : kAllReadings)
    out += (out.empty() ? "" : " | ") + ToString(how);
  return out;
}

}  // namespace handlabel
