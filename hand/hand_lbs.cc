#include "hand/hand_lbs.h"

#include <Eigen/Geometry>
#include <string>

#include "core/errors.h"
#include "hand/mesh_keypoints.h"
#include "hand/shaped_hand.h"

// Reference implementation with plain Eigen matrix algebra, written for clarity and
// kept independent of the templated HandEvaluator (hand_evaluator.h) so that each can
// check the other in tests.

namespace handlabel {
namespace {

Eigen::Matrix3d Rodrigues(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

}  // namespace

HandMesh PoseHand(const HandModel& model, const HandParams& params) {
  const int num_vertices = model.num_vertices();
  const ShapedHand shaped = ShapeHand(model, params.betas);
  // Row-major V x 3 storage flattens to index 3*v + c, the row order of the blend shapes.
  const Eigen::VectorXd v_shaped_flat =
      Eigen::Map<const Eigen::VectorXd>(shaped.vertices.data(), 3 * num_vertices);
  const Points3d& rest_joints = shaped.joints;

  std::array<Eigen::Matrix3d, kNumHandJoints> local;
  local[0] = Rodrigues(params.global_orient);
  Eigen::VectorXd pose_feature(9 * (kNumHandJoints - 1));
  for (int j = 1; j < kNumHandJoints; ++j) {
    local[j] = Rodrigues(params.hand_pose.segment<3>(3 * (j - 1)));
    const Eigen::Matrix3d d = local[j] - Eigen::Matrix3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int s = 0; s < 3; ++s) pose_feature[9 * (j - 1) + 3 * r + s] = d(r, s);
    }
  }
  const Eigen::VectorXd v_posed_flat = v_shaped_flat + model.posedirs * pose_feature;

  // World transforms G_j and skinning transforms A_j = G_j * [I | -J_j], stored as
  // flattened row-major 3x4 matrices so that blending is one matrix product.
  std::array<Eigen::Matrix3d, kNumHandJoints> world_r;
  std::array<Eigen::Vector3d, kNumHandJoints> world_t;
  Eigen::Matrix<double, kNumHandJoints, 12, Eigen::RowMajor> skin;
  for (int j = 0; j < kNumHandJoints; ++j) {
    const int parent = model.parents[j];
    const Eigen::Vector3d rest = rest_joints.row(j).transpose();
    if (parent < 0) {
      world_r[j] = local[j];
      world_t[j] = rest;
    } else {
      const Eigen::Vector3d offset = rest - rest_joints.row(parent).transpose();
      world_r[j] = world_r[parent] * local[j];
      world_t[j] = world_r[parent] * offset + world_t[parent];
    }
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> a;
    a.leftCols<3>() = world_r[j];
    a.col(3) = world_t[j] - world_r[j] * rest;
    skin.row(j) = Eigen::Map<const Eigen::Matrix<double, 1, 12>>(a.data());
  }

  const Eigen::Matrix<double, Eigen::Dynamic, 12, Eigen::RowMajor> blended =
      model.skinning_weights * skin;
  HandMesh mesh;
  mesh.vertices.resize(num_vertices, 3);
  for (int v = 0; v < num_vertices; ++v) {
    const Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> m(
        blended.row(v).data());
    mesh.vertices.row(v) =
        (m.leftCols<3>() * v_posed_flat.segment<3>(3 * v) + m.col(3) + params.transl)
            .transpose();
  }
  mesh.joints.resize(kNumHandJoints, 3);
  for (int j = 0; j < kNumHandJoints; ++j) {
    mesh.joints.row(j) = (world_t[j] + params.transl).transpose();
  }
  mesh.keypoints = SnapKeypoints(model, mesh.joints, mesh.vertices);
  return mesh;
}

Eigen::Matrix<double, kNumPoseParams, 1> HandPoseFromPca(const HandModel& model,
                                                         const Eigen::VectorXd& coeffs,
                                                         bool flat_hand_mean) {
  const Eigen::Index num_comps = model.pose_pca_basis.rows();
  if (model.pose_pca_basis.cols() != kNumPoseParams) {
    throw InputError(model.name, "hands_components", "a (n, 45) PCA basis",
                     "(" + std::to_string(num_comps) + ", " +
                         std::to_string(model.pose_pca_basis.cols()) + ")");
  }
  if (coeffs.size() > num_comps) {
    throw InputError("HandParams", "pca coefficients",
                     "at most " + std::to_string(num_comps),
                     std::to_string(coeffs.size()));
  }
  Eigen::Matrix<double, kNumPoseParams, 1> pose =
      model.pose_pca_basis.topRows(coeffs.size()).transpose() * coeffs;
  if (!flat_hand_mean) {
    if (model.pose_mean.size() != kNumPoseParams) {
      throw InputError(model.name, "hands_mean", "45 values (or use flat_hand_mean)",
                       std::to_string(model.pose_mean.size()));
    }
    pose += model.pose_mean;
  }
  return pose;
}

}  // namespace handlabel
