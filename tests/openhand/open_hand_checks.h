#pragma once
// Property checks of an open hand model, shared by the coarse-build tests and the
// tests of the shipped models/ files. Numbers are documented in docs/open-hand.md.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "hand/hand_anatomy.h"
#include "hand/hand_lbs.h"
#include "openhand/mesh_checks.h"

namespace handlabel::testing {

inline double HandLength(const HandModel& model) {
  const HandMesh m = PoseHand(model, HandParams());
  return (m.keypoints.row(0) - m.keypoints.row(12)).norm();  // wrist to middle tip
}

// Pose with one anatomical angle of one joint set (degrees), others zero.
inline HandParams PoseOneAngle(const HandAnatomy& anatomy, int joint, int axis,
                               double deg) {
  HandPoseVector angles = HandPoseVector::Zero();
  angles[3 * (joint - 1) + axis] = deg * M_PI / 180.0;
  HandParams p;
  p.hand_pose = HandPoseFromAnatomicalAngles(anatomy, angles);
  return p;
}

// A closed, outward-facing, self-intersection-free mesh of adult size.
inline void ExpectClosedAdultSurface(const HandModel& model) {
  const int nv = model.num_vertices();
  EXPECT_GE(nv, 700);
  EXPECT_LE(nv, 900);
  const MeshTopology topo = AnalyzeMeshTopology(nv, model.faces);
  EXPECT_TRUE(topo.IsClosedManifold())
      << "boundary " << topo.boundary_edges << " nonmanifold e/v "
      << topo.nonmanifold_edges << "/" << topo.nonmanifold_vertices << " misoriented "
      << topo.misoriented_edges << " components " << topo.components << " euler "
      << topo.euler_characteristic;
  EXPECT_GT(SignedVolume(model.v_template, model.faces), 0.0) << "normals point inwards";
  EXPECT_EQ(CountSelfIntersections(model.v_template, model.faces), 0);

  // Adult size: wrist to middle fingertip 17-20 cm (design: ~18.5 cm).
  const double length = HandLength(model);
  EXPECT_GT(length, 0.17);
  EXPECT_LT(length, 0.20);
}

// Skinning weights: non-negative rows summing to 1; joint regressor: convex
// combinations.
inline void ExpectConvexWeights(const HandModel& model) {
  EXPECT_GE(model.skinning_weights.minCoeff(), 0.0);
  for (int v = 0; v < model.num_vertices(); ++v)
    EXPECT_NEAR(model.skinning_weights.row(v).sum(), 1.0, 1e-12);
  for (int j = 0; j < kNumHandJoints; ++j) {
    double sum = 0.0;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(
             model.joint_regressor, j);
         it; ++it) {
      EXPECT_GT(it.value(), 0.0);
      sum += it.value();
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << "joint " << j;
  }
}

// MANO axes: fingers along -x (right) / +x (left), thumb on +z, back of hand +y; the
// palm centre's outward normal points -y.
inline void ExpectManoAxes(const HandModel& model) {
  const double sx = model.side == HandSide::kRight ? 1.0 : -1.0;
  const HandMesh rest = PoseHand(model, HandParams());
  const Eigen::Vector3d wrist = rest.keypoints.row(0);
  const Eigen::Vector3d middle_mcp = rest.keypoints.row(9),
                        middle_tip = rest.keypoints.row(12);
  EXPECT_LT(sx * (middle_tip - middle_mcp).normalized().x(), -0.95);
  EXPECT_LT(sx * (middle_mcp - wrist).normalized().x(), -0.95);
  const Eigen::Vector3d thumb_tip = rest.keypoints.row(4),
                        index_mcp = rest.keypoints.row(5),
                        pinky_mcp = rest.keypoints.row(17);
  EXPECT_GT(thumb_tip.z(), index_mcp.z() + 0.02);
  EXPECT_GT(index_mcp.z(), pinky_mcp.z() + 0.03);
  const Eigen::Vector3d palm_centre = (wrist + middle_mcp) / 2.0;
  Eigen::Index best = 0;
  double best_score = 1e9;
  for (int v = 0; v < model.num_vertices(); ++v) {
    const Eigen::Vector3d q = model.v_template.row(v).transpose() - palm_centre;
    const double score = std::hypot(q.x(), q.z()) - (q.y() < 0 ? 1.0 : 0.0);
    if (score < best_score) best_score = score, best = v;
  }
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int f = 0; f < model.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (model.faces(f, k) != best) continue;
      const Eigen::Vector3d a = model.v_template.row(model.faces(f, 0)),
                            b = model.v_template.row(model.faces(f, 1)),
                            c = model.v_template.row(model.faces(f, 2));
      normal += (b - a).cross(c - a);
    }
  }
  EXPECT_LT(normal.normalized().y(), -0.8)
      << "palm normal " << normal.normalized().transpose();
}

// Distinct tips; a positive bend flexes every finger towards the palm (-y); posed at
// every single-angle limit (DefaultHandLimits), few faces turn over.
inline void ExpectTipsBendAndLimits(const HandModel& model, const HandAnatomy& anatomy) {
  for (int a = 0; a < 5; ++a)
    for (int b = a + 1; b < 5; ++b)
      EXPECT_NE(model.tip_vertex_ids[a], model.tip_vertex_ids[b]);
  const HandMesh rest = PoseHand(model, HandParams());
  for (int first : {1, 4, 7, 10}) {
    const HandMesh bent = PoseHand(model, PoseOneAngle(anatomy, first, kBend, 60.0));
    const int tip_keypoint = first == 1 ? 8 : first == 4 ? 12 : first == 7 ? 20 : 16;
    EXPECT_LT(bent.keypoints(tip_keypoint, 1), rest.keypoints(tip_keypoint, 1) - 0.03);
  }
  const HandLimits limits = DefaultHandLimits();
  double worst = 0.0;
  for (int j = 1; j < kNumHandJoints; ++j) {
    for (int axis = 0; axis < 3; ++axis) {
      for (double deg :
           {limits.joints[j][axis].min_deg, limits.joints[j][axis].max_deg}) {
        if (deg == 0.0) continue;
        worst = std::max(
            worst, InvertedFaceFraction(model, PoseOneAngle(anatomy, j, axis, deg)));
      }
    }
  }
  EXPECT_LT(worst, 0.01) << "worst fraction of inverted faces at a single-joint limit";
}

// No candy-wrapper collapse: at a 90 degree bend the surface around the joint keeps
// most of its distance from the joint centre (measured 72-82 % on the shipped model).
inline void ExpectNoCandyWrapper(const HandModel& model, const HandAnatomy& anatomy) {
  const HandMesh rest_mesh = PoseHand(model, HandParams());
  for (int j : {1, 2, 4, 5, 10, 11, 7, 8, 14}) {
    const HandMesh bent = PoseHand(model, PoseOneAngle(anatomy, j, kBend, 90.0));
    double before = 1e9, after = 1e9;
    for (int v = 0; v < model.num_vertices(); ++v) {
      if (model.skinning_weights(v, j) + model.skinning_weights(v, model.parents[j]) <
          0.9)
        continue;
      before =
          std::min(before, (rest_mesh.vertices.row(v) - rest_mesh.joints.row(j)).norm());
      after = std::min(after, (bent.vertices.row(v) - bent.joints.row(j)).norm());
    }
    EXPECT_GT(after, 0.6 * before) << JointName(j) << " collapses at 90 degrees";
  }
}

// Pose PCA: orthonormal rows, 45 x 45; posedirs: zero (plain LBS, documented).
inline void ExpectPosePcaAndPlainLbs(const HandModel& model) {
  ASSERT_EQ(model.pose_pca_basis.rows(), kNumPoseParams);
  const Eigen::MatrixXd gram = model.pose_pca_basis * model.pose_pca_basis.transpose();
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(45, 45)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(model.posedirs.cwiseAbs().maxCoeff(), 0.0);
}

inline void ExpectPlausibleOpenHand(const HandModel& model) {
  ASSERT_NO_THROW(model.Check("open hand"));
  ExpectClosedAdultSurface(model);
  ExpectConvexWeights(model);
  ExpectManoAxes(model);
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  ExpectTipsBendAndLimits(model, anatomy);
  ExpectNoCandyWrapper(model, anatomy);
  ExpectPosePcaAndPlainLbs(model);
}

// `left` is the exact mirror image (x -> -x) of `right`.
inline void ExpectMirrorPair(const HandModel& right, const HandModel& left) {
  ASSERT_EQ(right.num_vertices(), left.num_vertices());
  ASSERT_EQ(right.num_faces(), left.num_faces());
  Points3d mirrored = right.v_template;
  mirrored.col(0) *= -1.0;
  EXPECT_TRUE(mirrored == left.v_template);
  for (int f = 0; f < right.num_faces(); ++f) {
    EXPECT_EQ(left.faces(f, 0), right.faces(f, 0));
    EXPECT_EQ(left.faces(f, 1), right.faces(f, 2));
    EXPECT_EQ(left.faces(f, 2), right.faces(f, 1));
  }
  EXPECT_TRUE(left.skinning_weights == right.skinning_weights);
  EXPECT_TRUE(Eigen::MatrixXd(left.joint_regressor) ==
              Eigen::MatrixXd(right.joint_regressor));
  EXPECT_EQ(left.tip_vertex_ids, right.tip_vertex_ids);
  // Posing with the mirrored parameters gives the mirrored mesh.
  HandParams p;
  p.global_orient = Eigen::Vector3d(0.3, -0.2, 0.1);
  for (int k = 0; k < kNumPoseParams; ++k) p.hand_pose[k] = 0.3 * std::sin(1.7 * k + 0.4);
  p.betas = Eigen::VectorXd::LinSpaced(right.num_betas(), -1.0, 1.0);
  p.transl = Eigen::Vector3d(0.01, 0.02, 0.5);
  HandParams q = p;
  auto mirror_aa = [](double* w) { w[1] = -w[1], w[2] = -w[2]; };
  mirror_aa(q.global_orient.data());
  for (int j = 0; j < 15; ++j) mirror_aa(q.hand_pose.data() + 3 * j);
  q.transl.x() *= -1.0;
  Points3d a = PoseHand(right, p).vertices;
  a.col(0) *= -1.0;
  const Points3d b = PoseHand(left, q).vertices;
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-12);
  // PCA poses mirror too.
  Eigen::VectorXd coeffs = Eigen::VectorXd::LinSpaced(6, -1.0, 1.5);
  auto pr = HandPoseFromPca(right, coeffs, false);
  auto pl = HandPoseFromPca(left, coeffs, false);
  for (int j = 0; j < 15; ++j) mirror_aa(pr.data() + 3 * j);
  EXPECT_LT((pr - pl).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace handlabel::testing
