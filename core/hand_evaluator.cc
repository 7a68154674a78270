#include "core/hand_evaluator.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "core/errors.h"

namespace handlabel {

void HandEvaluatorOptions::Check() const {
  if (num_betas < -1) {
    throw InputError("HandEvaluatorOptions", "num_betas", ">= 0, or -1 for all",
                     std::to_string(num_betas));
  }
  if (num_pca_comps < 0) {
    throw InputError("HandEvaluatorOptions", "num_pca_comps", ">= 0",
                     std::to_string(num_pca_comps));
  }
}

HandEvaluator::HandEvaluator(const HandModel& model, const HandEvaluatorOptions& options)
    : options_(options),
      num_vertices_(model.num_vertices()),
      parents_(model.parents),
      tip_vertex_ids_(model.tip_vertex_ids) {
  options.Check();
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

void HandEvaluator::KeypointsAndJacobian(const double* global_orient,
                                         const double* hand_pose, const double* betas,
                                         const double* transl, double* keypoints63,
                                         double* jacobian) const {
  using Vec3 = Eigen::Vector3d;
  using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  constexpr int kFeatures = 9 * (kNumHandJoints - 1);
  const int nb = num_betas_;
  const int np = num_params();
  const int col_betas = 3 + pose_dim();
  const int col_transl = col_betas + nb;

  HandPoseState<double> state;
  Pose(global_orient, hand_pose, betas, transl, &state);
  double pose45[kNumPoseParams];
  AxisAnglePose(hand_pose, pose45);

  // World rotation and position of every joint, and the world angular velocity
  // omega[j][i] of joint j's frame per unit change of its axis-angle component i:
  // a point q in j's subtree then moves by omega x (q - p_j).
  std::array<Mat3, kNumHandJoints> world_r;
  std::array<Vec3, kNumHandJoints> world_p;
  std::array<std::array<Vec3, 3>, kNumHandJoints> omega;
  double feature_jac[kFeatures][3];
  for (int j = 0; j < kNumHandJoints; ++j) {
    const double* g = state.world + 12 * j;
    world_r[j] << g[0], g[1], g[2], g[4], g[5], g[6], g[8], g[9], g[10];
    world_p[j] << g[3], g[7], g[11];
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
        if (j > 0) feature_jac[9 * (j - 1) + e][i] = rd[e].v[i];
      }
      const Mat3 skew = r.transpose() * dr;  // body-frame [omega]x
      omega[j][i] = world_r[j] * Vec3(skew(2, 1), skew(0, 2), skew(1, 0));
    }
  }
  // d p_j / d betas (3 x nb each): p_j = R_parent (J_j - J_parent) + p_parent.
  std::array<Eigen::Matrix<double, 3, Eigen::Dynamic>, kNumHandJoints> dp_dbetas;
  for (int j = 0; j < kNumHandJoints; ++j) {
    const Eigen::Matrix<double, 3, Eigen::Dynamic> dj =
        joint_shapedirs_.middleRows(3 * j, 3);
    const int parent = parents_[j];
    if (parent < 0) {
      dp_dbetas[j] = dj;
    } else {
      dp_dbetas[j] = world_r[parent] * (dj - joint_shapedirs_.middleRows(3 * parent, 3)) +
                     dp_dbetas[parent];
    }
  }

  // Jacobian w.r.t. axis-angle pose (45 columns) first; mapped to PCA at the end.
  Eigen::Matrix<double, 3, kNumPoseParams> d_pose;
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> jac(
      jacobian, 3 * kNumHandKeypoints, np);
  jac.setZero();
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int native = kSnapFromNative[k];
    auto rows = jac.middleRows<3>(3 * k);
    Eigen::Matrix3d d_orient = Eigen::Matrix3d::Zero();
    d_pose.setZero();
    Vec3 point;
    if (native < kNumHandJoints) {
      point = world_p[native];
      // Every ancestor-or-self a rotates p about p_a.
      for (int a = native; a >= 0; a = parents_[a]) {
        for (int i = 0; i < 3; ++i) {
          const Vec3 d = omega[a][i].cross(point - world_p[a]);
          if (a == 0) {
            d_orient.col(i) = d;
          } else {
            d_pose.col(3 * (a - 1) + i) = d;
          }
        }
      }
      rows.middleCols(col_betas, nb) = dp_dbetas[native];
    } else {
      const int v = tip_vertex_ids_[native - kNumHandJoints];
      // v_posed and its derivatives.
      Vec3 vp;
      Eigen::Matrix<double, 3, kNumPoseParams> dvp_dpose =
          Eigen::Matrix<double, 3, kNumPoseParams>::Zero();
      for (int c = 0; c < 3; ++c) {
        const Eigen::Index row = 3 * v + c;
        double value = v_template_[row];
        for (int s = 0; s < nb; ++s) value += shapedirs_(row, s) * state.betas[s];
        const double* pd = posedirs_.data() + row * kFeatures;
        for (int f = 0; f < kFeatures; ++f) {
          value += pd[f] * state.pose_feature[f];
          for (int i = 0; i < 3; ++i)
            dvp_dpose(c, 3 * (f / 9) + i) += pd[f] * feature_jac[f][i];
        }
        vp[c] = value;
      }
      // Blend: point = sum_j w_j q_j, q_j = R_j (vp - J_j) + p_j; s_a collects
      // w_j (q_j - p_a) over the joints j in the subtree of a.
      Mat3 blended_r = Mat3::Zero();
      point.setZero();
      std::array<Vec3, kNumHandJoints> moment;
      for (Vec3& m : moment) m.setZero();
      Eigen::Matrix<double, 3, Eigen::Dynamic> d_betas =
          Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, nb);
      for (int e = weight_start_[v]; e < weight_start_[v + 1]; ++e) {
        const int j = weight_joint_[e];
        const double w = weight_value_[e];
        const Vec3 rest(state.rest_joints[3 * j], state.rest_joints[3 * j + 1],
                        state.rest_joints[3 * j + 2]);
        const Vec3 q = world_r[j] * (vp - rest) + world_p[j];
        point += w * q;
        blended_r += w * world_r[j];
        for (int a = j; a >= 0; a = parents_[a]) moment[a] += w * (q - world_p[a]);
        d_betas +=
            w * (dp_dbetas[j] - world_r[j] * joint_shapedirs_.middleRows(3 * j, 3));
      }
      for (int a = 0; a < kNumHandJoints; ++a) {
        for (int i = 0; i < 3; ++i) {
          const Vec3 d = omega[a][i].cross(moment[a]);
          if (a == 0) {
            d_orient.col(i) = d;
          } else {
            d_pose.col(3 * (a - 1) + i) = d;
          }
        }
      }
      d_pose += blended_r * dvp_dpose;
      rows.middleCols(col_betas, nb) =
          d_betas + blended_r * shapedirs_.middleRows(3 * v, 3);
    }
    rows.leftCols<3>() = d_orient;
    if (options_.num_pca_comps > 0) {
      rows.middleCols(3, pose_dim()) = d_pose * pca_basis_.transpose();
    } else {
      rows.middleCols<kNumPoseParams>(3) = d_pose;
    }
    rows.middleCols<3>(col_transl).setIdentity();
    for (int c = 0; c < 3; ++c) {
      keypoints63[3 * k + c] = point[c] + state.transl[c];
    }
  }
}

}  // namespace handlabel
