#pragma once
// A tiny MANO-layout hand for anatomy tests: 21 vertices = the 16 joints + 5 tips,
// fingers along -x, back of the hand +y (palm -y), thumb +z, as MANO and the open hand.
// Vertex v is rigidly attached to the parent of joint v (tips to the last joint).
// The index finger is exactly straight along -x so its frames are axis aligned.
// MakeStickHand(kLeft) is the exact mirror x -> -x, blend shapes included.

#include <random>

#include "hand/hand_model.h"
#include "hand/hand_rest_skeleton.h"

namespace handlabel::testing {

inline HandModel MakeStickHand(HandSide side) {
  const auto& p = kRestSkeleton;
  const int kVerts = 21;
  const double mirror = side == HandSide::kLeft ? -1.0 : 1.0;
  const double m[3] = {mirror, 1.0, 1.0};
  HandModel model;
  model.name = side == HandSide::kLeft ? "stick_left" : "stick_right";
  model.side = side;
  model.v_template.resize(kVerts, 3);
  for (int v = 0; v < kVerts; ++v) {
    for (int c = 0; c < 3; ++c) model.v_template(v, c) = m[c] * p[v][c];
  }
  model.faces.resize(1, 3);
  model.faces << 0, 1, 2;
  model.tip_vertex_ids = {16, 17, 18, 19, 20};
  std::mt19937_64 rng(7);  // same blend shapes on both sides, mirrored
  std::normal_distribution<double> g(0.0, 0.003);
  model.shapedirs.resize(3 * kVerts, 10);
  model.posedirs.resize(3 * kVerts, 135);
  for (int v = 0; v < kVerts; ++v) {
    for (int c = 0; c < 3; ++c) {
      for (int s = 0; s < 10; ++s) model.shapedirs(3 * v + c, s) = m[c] * g(rng);
      for (int k = 0; k < 135; ++k) {
        const int r = (k % 9) / 3, q = k % 3;
        model.posedirs(3 * v + c, k) = m[c] * m[r] * m[q] * g(rng);
      }
    }
  }
  std::vector<Eigen::Triplet<double>> reg;
  for (int j = 0; j < kNumHandJoints; ++j) reg.emplace_back(j, j, 1.0);
  model.joint_regressor.resize(kNumHandJoints, kVerts);
  model.joint_regressor.setFromTriplets(reg.begin(), reg.end());
  model.skinning_weights.setZero(kVerts, kNumHandJoints);
  const int tip_parent[5] = {15, 3, 6, 12, 9};
  for (int v = 0; v < kVerts; ++v) {
    const int bone =
        v < kNumHandJoints ? std::max(0, kManoParents[v]) : tip_parent[v - 16];
    model.skinning_weights(v, bone) = 1.0;
  }
  model.Check(model.name);
  return model;
}

}  // namespace handlabel::testing
