#include "hand/capsule_hand.h"

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "hand/hand_rest_skeleton.h"

namespace handlabel {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Builder {
  std::vector<Eigen::Vector3d> v;
  std::vector<int> bone;  // skinning joint per vertex
  std::vector<Eigen::Vector3i> f;
};

// A capsule from a to b with `radius`, skinned rigidly to `joint`; returns the index of
// the pole vertex beyond b.
int AddCapsule(Builder* m, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
               double radius, int joint) {
  const int kSeg = 10, kCap = 3;  // segments around, rings per hemisphere
  const Eigen::Vector3d axis = (b - a).normalized();
  const double length = (b - a).norm();
  Eigen::Vector3d u = axis.unitOrthogonal();
  Eigen::Vector3d w = axis.cross(u);
  // Rings: kCap over the back hemisphere, kCap over the front, poles separately.
  std::vector<std::pair<double, double>> rings;  // (position along axis, radius)
  for (int i = 1; i <= kCap; ++i) {
    const double phi = kPi / 2 * (1.0 - static_cast<double>(i) / (kCap + 1));  // > 0
    rings.emplace_back(-radius * std::sin(phi), radius * std::cos(phi));
  }
  rings.emplace_back(0.0, radius);
  rings.emplace_back(length, radius);
  for (int i = kCap; i >= 1; --i) {
    const double phi = kPi / 2 * (1.0 - static_cast<double>(i) / (kCap + 1));
    rings.emplace_back(length + radius * std::sin(phi), radius * std::cos(phi));
  }
  const int start = static_cast<int>(m->v.size());
  m->v.push_back(a - radius * axis);
  m->bone.push_back(joint);
  for (const auto& [s, r] : rings) {
    for (int k = 0; k < kSeg; ++k) {
      const double t = 2 * kPi * k / kSeg;
      m->v.push_back(a + s * axis + r * (std::cos(t) * u + std::sin(t) * w));
      m->bone.push_back(joint);
    }
  }
  const int tip = static_cast<int>(m->v.size());
  m->v.push_back(b + radius * axis);
  m->bone.push_back(joint);
  const int nr = static_cast<int>(rings.size());
  auto ring_vertex = [&](int ring, int k) { return start + 1 + ring * kSeg + k % kSeg; };
  // Orientation: (u, w, axis) is right-handed, so (ring k, ring k+1 along +axis) ...
  for (int k = 0; k < kSeg; ++k) {
    m->f.emplace_back(start, ring_vertex(0, k + 1), ring_vertex(0, k));
    for (int r = 0; r + 1 < nr; ++r) {
      const int a0 = ring_vertex(r, k), a1 = ring_vertex(r, k + 1);
      const int b0 = ring_vertex(r + 1, k), b1 = ring_vertex(r + 1, k + 1);
      m->f.emplace_back(a0, a1, b1);
      m->f.emplace_back(a0, b1, b0);
    }
    m->f.emplace_back(tip, ring_vertex(nr - 1, k), ring_vertex(nr - 1, k + 1));
  }
  return tip;
}

// Ellipsoid palm around `centre` with semi-axes `radii`, skinned to the wrist.
void AddPalm(Builder* m, const Eigen::Vector3d& centre, const Eigen::Vector3d& radii) {
  const int kRings = 10, kSeg = 16;
  const int start = static_cast<int>(m->v.size());
  for (int i = 0; i <= kRings; ++i) {
    const double theta = kPi * i / kRings;
    for (int j = 0; j < kSeg; ++j) {
      const double phi = 2 * kPi * j / kSeg;
      const Eigen::Vector3d n(std::cos(theta), std::sin(theta) * std::cos(phi),
                              std::sin(theta) * std::sin(phi));
      m->v.push_back(centre + radii.cwiseProduct(n));
      m->bone.push_back(0);
    }
  }
  for (int i = 0; i < kRings; ++i) {
    for (int j = 0; j < kSeg; ++j) {
      const int a = start + i * kSeg + j, b = start + i * kSeg + (j + 1) % kSeg;
      const int c = a + kSeg, d = b + kSeg;
      m->f.emplace_back(a, d, b);  // outward: (c - a) x (d - a) points out
      m->f.emplace_back(a, c, d);
    }
  }
}

}  // namespace

HandModel MakeCapsuleHand(HandSide side) {
  Builder m;
  std::vector<Eigen::Vector3d> p(21);
  for (int i = 0; i < 21; ++i)
    p[i] = Eigen::Vector3d(kRestSkeleton[i][0], kRestSkeleton[i][1], kRestSkeleton[i][2]);
  // Hidden joint vertices first: vertex j = joint j, moving with its parent.
  for (int j = 0; j < kNumHandJoints; ++j) {
    m.v.push_back(p[j]);
    m.bone.push_back(std::max(0, kManoParents[j]));
  }
  AddPalm(&m, Eigen::Vector3d(-0.05, -0.002, -0.002),
          Eigen::Vector3d(0.055, 0.016, 0.047));
  // Chains (native joint ids) and their fingertip index in p (16 + tip order).
  const int chains[5][3] = {{13, 14, 15}, {1, 2, 3}, {4, 5, 6}, {10, 11, 12}, {7, 8, 9}};
  const double radii[5] = {0.0105, 0.0092, 0.0095, 0.0088, 0.0080};
  std::array<int, 5> tips{};
  for (int finger = 0; finger < 5; ++finger) {
    for (int k = 0; k < 3; ++k) {
      const int joint = chains[finger][k];
      const Eigen::Vector3d& end = k < 2 ? p[chains[finger][k + 1]] : p[16 + finger];
      const double r = radii[finger] * (1.0 - 0.08 * k);
      const int pole = AddCapsule(&m, p[joint], end, r, joint);
      // The fingertip keypoint is the pole beyond the last bone, on the surface.
      if (k == 2) tips[finger] = pole;
    }
  }

  const int nv = static_cast<int>(m.v.size());
  const double mirror = side == HandSide::kLeft ? -1.0 : 1.0;
  HandModel model;
  model.name = side == HandSide::kLeft ? "capsule_hand_left" : "capsule_hand_right";
  model.side = side;
  model.v_template.resize(nv, 3);
  for (int i = 0; i < nv; ++i) {
    model.v_template.row(i) =
        Eigen::RowVector3d(mirror * m.v[i].x(), m.v[i].y(), m.v[i].z());
  }
  model.faces.resize(m.f.size(), 3);
  for (size_t i = 0; i < m.f.size(); ++i) {
    // Mirroring flips orientation; swap two corners to keep faces outward.
    model.faces.row(i) = side == HandSide::kLeft
                             ? Eigen::RowVector3i(m.f[i][0], m.f[i][2], m.f[i][1])
                             : Eigen::RowVector3i(m.f[i].transpose());
  }
  model.shapedirs = Eigen::MatrixXd::Zero(3 * nv, 10);
  for (int i = 0; i < nv; ++i) {
    for (int c = 0; c < 3; ++c) {
      model.shapedirs(3 * i + c, 0) = 0.1 * model.v_template(i, c);
    }
    model.shapedirs(3 * i + 0, 1) = 0.1 * model.v_template(i, 0);
    model.shapedirs(3 * i + 1, 2) = 0.1 * model.v_template(i, 1);
    model.shapedirs(3 * i + 2, 3) = 0.1 * model.v_template(i, 2);
  }
  model.posedirs = Eigen::MatrixXd::Zero(3 * nv, 135);
  std::vector<Eigen::Triplet<double>> reg;
  for (int j = 0; j < kNumHandJoints; ++j) reg.emplace_back(j, j, 1.0);
  model.joint_regressor.resize(kNumHandJoints, nv);
  model.joint_regressor.setFromTriplets(reg.begin(), reg.end());
  model.skinning_weights.setZero(nv, kNumHandJoints);
  for (int i = 0; i < nv; ++i) model.skinning_weights(i, m.bone[i]) = 1.0;
  model.tip_vertex_ids = tips;
  model.pose_pca_basis = Eigen::MatrixXd::Identity(kNumPoseParams, kNumPoseParams);
  model.pose_mean = Eigen::VectorXd::Zero(kNumPoseParams);
  model.Check(model.name);
  return model;
}

}  // namespace handlabel
