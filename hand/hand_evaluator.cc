#include "hand/hand_evaluator.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

void HandEvaluatorOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "num_betas", num_betas, -1, ">= 0, or -1 for all");
  RequireAtLeast(source, "num_pca_comps", num_pca_comps, 0);
}

HandEvaluator::HandEvaluator(const HandModel& model, const HandEvaluatorOptions& options)
    : options_(options),
      num_vertices_(model.num_vertices()),
      parents_(model.parents),
      tip_vertex_ids_(model.tip_vertex_ids) {
  options.Check("HandEvaluatorOptions");
  const std::string source = "HandEvaluatorOptions (model " + model.name + ")";
  num_betas_ = options.num_betas < 0 ? model.num_betas() : options.num_betas;
  if (num_betas_ > model.num_betas() || num_betas_ > kMaxHandBetas) {
    throw InputError(
        source, "num_betas",
        "-1 or at most " + std::to_string(std::min(model.num_betas(), kMaxHandBetas)),
        std::to_string(options.num_betas));
  }
  if (options.num_pca_comps < 0 || options.num_pca_comps > model.pose_pca_basis.rows()) {
    throw InputError(
        source, "num_pca_comps",
        "0 (axis-angle) or 1.." + std::to_string(model.pose_pca_basis.rows()),
        std::to_string(options.num_pca_comps));
  }
  HL_CHECK(model.v_template.rows() * 3 == model.posedirs.rows() &&
               model.posedirs.cols() == 9 * (kNumHandJoints - 1) &&
               model.joint_regressor.rows() == kNumHandJoints &&
               model.joint_regressor.cols() == model.v_template.rows() &&
               model.skinning_weights.rows() == model.v_template.rows(),
           "HandModel arrays inconsistent; call HandModel::Check after loading");

  const int v3 = 3 * num_vertices_;
  v_template_ = Eigen::Map<const Eigen::VectorXd>(model.v_template.data(), v3);
  shapedirs_ = model.shapedirs.leftCols(num_betas_);
  posedirs_ = model.posedirs;

  // Joints are linear in betas: J = R (T + S b) = R T + (R S) b, with R the regressor
  // applied per coordinate.
  const Eigen::MatrixXd joints_template = model.joint_regressor * model.v_template;
  joint_shapedirs_ = RowMatrix::Zero(3 * kNumHandJoints, num_betas_);
  for (int j = 0; j < kNumHandJoints; ++j) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(
             model.joint_regressor, j);
         it; ++it) {
      for (int c = 0; c < 3; ++c) {
        joint_shapedirs_.row(3 * j + c) += it.value() * shapedirs_.row(3 * it.col() + c);
      }
    }
    for (int c = 0; c < 3; ++c) joint_template_[3 * j + c] = joints_template(j, c);
  }

  weight_start_.assign(1, 0);
  for (int v = 0; v < num_vertices_; ++v) {
    for (int j = 0; j < kNumHandJoints; ++j) {
      const double w = model.skinning_weights(v, j);
      if (w == 0.0) continue;
      weight_joint_.push_back(j);
      weight_value_.push_back(w);
    }
    weight_start_.push_back(static_cast<int>(weight_joint_.size()));
  }

  if (options.num_pca_comps > 0) {
    if (model.pose_pca_basis.cols() != kNumPoseParams) {
      throw InputError(source, "hands_components", "a (n, 45) PCA basis",
                       std::to_string(model.pose_pca_basis.cols()) + " columns");
    }
    pca_basis_ = model.pose_pca_basis.topRows(options.num_pca_comps);
    if (!options.flat_hand_mean) {
      if (model.pose_mean.size() != kNumPoseParams) {
        throw InputError(source, "hands_mean", "45 values (or flat_hand_mean)",
                         std::to_string(model.pose_mean.size()));
      }
      pca_mean_ = model.pose_mean;
    }
  }
}

}  // namespace handlabel

namespace handlabel {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using BetaColumns = Eigen::Matrix<double, 3, Eigen::Dynamic>;
using PoseColumns = Eigen::Matrix<double, 3, kNumPoseParams>;
constexpr int kFeatures = 9 * (kNumHandJoints - 1);

// World rotation and position of every joint, and the world angular velocity
// omega[j][i] of joint j's frame per unit change of its axis-angle component i: a point
// q in j's subtree then moves by omega x (q - p_j). feature_jac holds the derivatives
// of the pose features (rotation entries of joints 1..15) by their axis-angle.
struct JointMotion {
  std::array<Mat3, kNumHandJoints> world_r;
  std::array<Vec3, kNumHandJoints> world_p;
  std::array<std::array<Vec3, 3>, kNumHandJoints> omega;
  double feature_jac[kFeatures][3];
};

void ComputeJointMotion(const HandPoseState<double>& state, const double* global_orient,
                        const double* pose45, JointMotion* m) {
  for (int j = 0; j < kNumHandJoints; ++j) {
    const double* g = state.world + 12 * j;
    m->world_r[j] << g[0], g[1], g[2], g[4], g[5], g[6], g[8], g[9], g[10];
    m->world_p[j] << g[3], g[7], g[11];
    const double* w = j == 0 ? global_orient : pose45 + 3 * (j - 1);
    Dual<3> wd[3] = {Dual<3>(w[0], 0), Dual<3>(w[1], 1), Dual<3>(w[2], 2)};
    Dual<3> rd[9];
    AxisAngleToRotation(wd, rd);
    Mat3 r;
    for (int e = 0; e < 9; ++e) r(e / 3, e % 3) = rd[e].a;
    for (int i = 0; i < 3; ++i) {
      Mat3 dr;
      for (int e = 0; e < 9; ++e) {
        dr(e / 3, e % 3) = rd[e].v[i];
        if (j > 0) m->feature_jac[9 * (j - 1) + e][i] = rd[e].v[i];
      }
      const Mat3 skew = r.transpose() * dr;  // body-frame [omega]x
      m->omega[j][i] = m->world_r[j] * Vec3(skew(2, 1), skew(0, 2), skew(1, 0));
    }
  }
}

// d p_j / d betas (3 x nb each): p_j = R_parent (J_j - J_parent) + p_parent.
std::array<BetaColumns, kNumHandJoints> JointBetaJacobians(
    const RowMatrix& joint_shapedirs, const std::array<int, kNumHandJoints>& parents,
    const JointMotion& m) {
  std::array<BetaColumns, kNumHandJoints> dp_dbetas;
  for (int j = 0; j < kNumHandJoints; ++j) {
    const BetaColumns dj = joint_shapedirs.middleRows(3 * j, 3);
    const int parent = parents[j];
    if (parent < 0) {
      dp_dbetas[j] = dj;
    } else {
      dp_dbetas[j] =
          m.world_r[parent] * (dj - joint_shapedirs.middleRows(3 * parent, 3)) +
          dp_dbetas[parent];
    }
  }
  return dp_dbetas;
}

// Stores d / d(axis-angle component i of joint a): joint 0 is the global orientation.
void SetRotationColumn(int a, int i, const Vec3& d, Eigen::Matrix3d* d_orient,
                       PoseColumns* d_pose) {
  if (a == 0) {
    d_orient->col(i) = d;
  } else {
    d_pose->col(3 * (a - 1) + i) = d;
  }
}

// The posed position of a joint keypoint and its rotation derivatives: every
// ancestor-or-self a rotates p about p_a.
Vec3 JointKeypoint(const JointMotion& m, const std::array<int, kNumHandJoints>& parents,
                   int joint, Eigen::Matrix3d* d_orient, PoseColumns* d_pose) {
  const Vec3 point = m.world_p[joint];
  for (int a = joint; a >= 0; a = parents[a]) {
    for (int i = 0; i < 3; ++i) {
      SetRotationColumn(a, i, m.omega[a][i].cross(point - m.world_p[a]), d_orient,
                        d_pose);
    }
  }
  return point;
}

// The evaluator's arrays that skinning one vertex reads.
struct SkinningArrays {
  const Eigen::VectorXd& v_template;  // 3V
  const RowMatrix& shapedirs;         // 3V x nb
  const RowMatrix& posedirs;          // 3V x 135
  const RowMatrix& joint_shapedirs;   // 48 x nb
  const std::vector<int>& weight_start;
  const std::vector<int>& weight_joint;
  const std::vector<double>& weight_value;
  const std::array<int, kNumHandJoints>& parents;
  int nb;
};

// Vertex v after shape and pose blend shapes (rest frame), and its pose derivatives.
Vec3 BlendedVertex(const SkinningArrays& s, const HandPoseState<double>& state,
                   const JointMotion& m, int v, PoseColumns* dvp_dpose) {
  Vec3 vp;
  dvp_dpose->setZero();
  for (int c = 0; c < 3; ++c) {
    const Eigen::Index row = 3 * v + c;
    double value = s.v_template[row];
    for (int b = 0; b < s.nb; ++b) value += s.shapedirs(row, b) * state.betas[b];
    const double* pd = s.posedirs.data() + row * kFeatures;
    for (int f = 0; f < kFeatures; ++f) {
      value += pd[f] * state.pose_feature[f];
      for (int i = 0; i < 3; ++i)
        (*dvp_dpose)(c, 3 * (f / 9) + i) += pd[f] * m.feature_jac[f][i];
    }
    vp[c] = value;
  }
  return vp;
}

// The posed position of vertex v (before transl) and its derivatives (rotation columns
// into d_orient / d_pose, shape columns into d_shape).
Vec3 SkinnedVertex(const SkinningArrays& s, const HandPoseState<double>& state,
                   const JointMotion& m,
                   const std::array<BetaColumns, kNumHandJoints>& dp_dbetas, int v,
                   Eigen::Matrix3d* d_orient, PoseColumns* d_pose, BetaColumns* d_shape) {
  PoseColumns dvp_dpose;
  const Vec3 vp = BlendedVertex(s, state, m, v, &dvp_dpose);
  // Blend: point = sum_j w_j q_j, q_j = R_j (vp - J_j) + p_j; s_a collects
  // w_j (q_j - p_a) over the joints j in the subtree of a.
  Mat3 blended_r = Mat3::Zero();
  Vec3 point = Vec3::Zero();
  std::array<Vec3, kNumHandJoints> moment;
  for (Vec3& mo : moment) mo.setZero();
  BetaColumns d_betas = BetaColumns::Zero(3, s.nb);
  for (int e = s.weight_start[v]; e < s.weight_start[v + 1]; ++e) {
    const int j = s.weight_joint[e];
    const double w = s.weight_value[e];
    const Vec3 rest(state.rest_joints[3 * j], state.rest_joints[3 * j + 1],
                    state.rest_joints[3 * j + 2]);
    const Vec3 q = m.world_r[j] * (vp - rest) + m.world_p[j];
    point += w * q;
    blended_r += w * m.world_r[j];
    for (int a = j; a >= 0; a = s.parents[a]) moment[a] += w * (q - m.world_p[a]);
    d_betas += w * (dp_dbetas[j] - m.world_r[j] * s.joint_shapedirs.middleRows(3 * j, 3));
  }
  for (int a = 0; a < kNumHandJoints; ++a) {
    for (int i = 0; i < 3; ++i) {
      SetRotationColumn(a, i, m.omega[a][i].cross(moment[a]), d_orient, d_pose);
    }
  }
  *d_pose += blended_r * dvp_dpose;
  *d_shape = d_betas + blended_r * s.shapedirs.middleRows(3 * v, 3);
  return point;
}

}  // namespace

// What every analytic Jacobian of one parameter vector shares: the forward pass, the
// joints' motion and the joints' shape derivatives.
struct HandEvaluator::JacobianPass {
  HandPoseState<double> state;
  JointMotion motion;
  std::array<BetaColumns, kNumHandJoints> dp_dbetas;
};

void HandEvaluator::PrepareJacobian(const double* global_orient, const double* hand_pose,
                                    const double* betas, const double* transl,
                                    JacobianPass* pass) const {
  Pose(global_orient, hand_pose, betas, transl, &pass->state);
  double pose45[kNumPoseParams];
  AxisAnglePose(hand_pose, pose45);
  ComputeJointMotion(pass->state, global_orient, pose45, &pass->motion);
  pass->dp_dbetas = JointBetaJacobians(joint_shapedirs_, parents_, pass->motion);
}

void HandEvaluator::WriteJacobianRows(const Eigen::Matrix3d& d_orient,
                                      const PoseColumns& d_pose,
                                      const BetaColumns& d_shape, double* rows) const {
  Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> out(rows, 3,
                                                                            num_params());
  const int col_betas = 3 + pose_dim();
  out.leftCols<3>() = d_orient;
  if (options_.num_pca_comps > 0) {
    out.middleCols(3, pose_dim()) = d_pose * pca_basis_.transpose();
  } else {
    out.middleCols<kNumPoseParams>(3) = d_pose;
  }
  out.middleCols(col_betas, num_betas_) = d_shape;
  out.middleCols<3>(col_betas + num_betas_).setIdentity();
}

void HandEvaluator::KeypointsAndJacobian(const double* global_orient,
                                         const double* hand_pose, const double* betas,
                                         const double* transl, double* keypoints63,
                                         double* jacobian) const {
  JacobianPass pass;
  PrepareJacobian(global_orient, hand_pose, betas, transl, &pass);
  const SkinningArrays arrays{v_template_,      shapedirs_,    posedirs_,
                              joint_shapedirs_, weight_start_, weight_joint_,
                              weight_value_,    parents_,      num_betas_};
  // Jacobian w.r.t. axis-angle pose (45 columns) first; mapped to PCA when written.
  PoseColumns d_pose;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int native = kSnapFromNative[k];
    Eigen::Matrix3d d_orient = Eigen::Matrix3d::Zero();
    d_pose.setZero();
    BetaColumns d_shape;
    Vec3 point;
    if (native < kNumHandJoints) {
      point = JointKeypoint(pass.motion, parents_, native, &d_orient, &d_pose);
      d_shape = pass.dp_dbetas[native];
    } else {
      point = SkinnedVertex(arrays, pass.state, pass.motion, pass.dp_dbetas,
                            tip_vertex_ids_[native - kNumHandJoints], &d_orient, &d_pose,
                            &d_shape);
    }
    WriteJacobianRows(d_orient, d_pose, d_shape, jacobian + 3 * k * num_params());
    for (int c = 0; c < 3; ++c) keypoints63[3 * k + c] = point[c] + pass.state.transl[c];
  }
}

void HandEvaluator::VerticesAndJacobian(const double* global_orient,
                                        const double* hand_pose, const double* betas,
                                        const double* transl, const std::vector<int>& ids,
                                        double* out, double* jacobian) const {
  JacobianPass pass;
  PrepareJacobian(global_orient, hand_pose, betas, transl, &pass);
  const SkinningArrays arrays{v_template_,      shapedirs_,    posedirs_,
                              joint_shapedirs_, weight_start_, weight_joint_,
                              weight_value_,    parents_,      num_betas_};
  PoseColumns d_pose;
  for (size_t i = 0; i < ids.size(); ++i) {
    HL_CHECK(
        ids[i] >= 0 && ids[i] < num_vertices_,
        "vertex id " + std::to_string(ids[i]) + " of " + std::to_string(num_vertices_));
    Eigen::Matrix3d d_orient = Eigen::Matrix3d::Zero();
    d_pose.setZero();
    BetaColumns d_shape;
    const Vec3 point = SkinnedVertex(arrays, pass.state, pass.motion, pass.dp_dbetas,
                                     ids[i], &d_orient, &d_pose, &d_shape);
    WriteJacobianRows(d_orient, d_pose, d_shape, jacobian + 3 * i * num_params());
    for (int c = 0; c < 3; ++c) out[3 * i + c] = point[c] + pass.state.transl[c];
  }
}

}  // namespace handlabel
