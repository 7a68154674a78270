#pragma once
// A MANO-structured test hand with a surface: the stick hand's 16 joints and 5 tips
// (tests/hand/stick_hand.h) plus closed tubes along every bone (palm bones from the
// wrist to each finger's first joint included) and balls at the joints and tips.
// Tube vertices are rigidly skinned to the bone's first joint and follow the joints'
// shape blend shapes (interpolated along the bone), so betas change bone lengths and
// the silhouette together. Kept for the silhouette fit test (ceres_hand_fitter_test):
// with the capsule hand (hand/capsule_hand.h) the same noise-free fit stays at
// 1.6-2.0 mm vertex error and IoU 0.87-0.90, outside that test's bounds.

#include <Eigen/Geometry>
#include <vector>

#include "image/mesh_primitives.h"
#include "tests/hand/stick_hand.h"

namespace handlabel::testing {

inline HandModel MakeTubeHand() {
  HandModel stick = MakeStickHand(HandSide::kRight);
  const int base = stick.num_vertices();  // 21
  // Bones (start joint, end vertex of the stick model) and radius.
  struct Bone {
    int start, end;
    double radius;
  };
  std::vector<Bone> bones;
  const int tip_of_chain[5] = {17, 18, 20, 19, 16};  // index, middle, pinky, ring, thumb
  for (int chain = 0; chain < 5; ++chain) {
    const int first = 1 + 3 * chain;
    const double r = chain == 4 ? 0.0095 : 0.0085;
    bones.push_back({0, first, 0.012});
    bones.push_back({first, first + 1, r});
    bones.push_back({first + 1, first + 2, r * 0.92});
    bones.push_back({first + 2, tip_of_chain[chain], r * 0.85});
  }
  std::vector<Eigen::Vector3d> verts;
  std::vector<Eigen::Vector3i> faces;
  std::vector<int> bone_joint;                // skinning joint per new vertex
  std::vector<std::pair<int, double>> along;  // (bone, t) for shape blending
  for (size_t b = 0; b < bones.size(); ++b) {
    const Eigen::Vector3d p0 = stick.v_template.row(bones[b].start).transpose();
    const Eigen::Vector3d p1 = stick.v_template.row(bones[b].end).transpose();
    const double length = (p1 - p0).norm();
    RenderMesh tube = MakeCylinder(bones[b].radius, length, 12, 8);
    // Cylinder axis z -> bone direction, centred at the bone's midpoint.
    const Eigen::Quaterniond q =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), (p1 - p0) / length);
    TransformMesh(Rigid3(q, 0.5 * (p0 + p1)), &tube);
    const int offset = base + static_cast<int>(verts.size());
    for (int v = 0; v < tube.vertices.rows(); ++v) {
      const Eigen::Vector3d x = tube.vertices.row(v).transpose();
      verts.push_back(x);
      bone_joint.push_back(bones[b].start);
      along.emplace_back(static_cast<int>(b),
                         std::clamp((x - p0).dot(p1 - p0) / (length * length), 0.0, 1.0));
    }
    for (int f = 0; f < tube.faces.rows(); ++f) {
      faces.emplace_back(tube.faces(f, 0) + offset, tube.faces(f, 1) + offset,
                         tube.faces(f, 2) + offset);
    }
  }
  HandModel model = stick;
  model.name = "tube_hand";
  const int n = base + static_cast<int>(verts.size());
  model.v_template.conservativeResize(n, 3);
  model.shapedirs.conservativeResize(3 * n, Eigen::NoChange);
  model.posedirs.conservativeResize(3 * n, Eigen::NoChange);
  model.skinning_weights.conservativeResize(n, Eigen::NoChange);
  for (size_t i = 0; i < verts.size(); ++i) {
    const int v = base + static_cast<int>(i);
    model.v_template.row(v) = verts[i].transpose();
    const Bone& bone = bones[along[i].first];
    const double t = along[i].second;
    for (int c = 0; c < 3; ++c) {
      model.shapedirs.row(3 * v + c) = (1 - t) * stick.shapedirs.row(3 * bone.start + c) +
                                       t * stick.shapedirs.row(3 * bone.end + c);
      model.posedirs.row(3 * v + c).setZero();
    }
    model.skinning_weights.row(v).setZero();
    model.skinning_weights(v, bone_joint[i]) = 1.0;
  }
  model.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) model.faces.row(f) = faces[f].transpose();
  model.joint_regressor.conservativeResize(kNumHandJoints, n);
  // The stick hand's random pose blend shapes would move its joint and tip vertices
  // off the tubes.
  model.posedirs.setZero();
  model.Check(model.name);
  return model;
}

}  // namespace handlabel::testing
