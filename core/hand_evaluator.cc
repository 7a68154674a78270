#include "core/hand_evaluator.h"

#include <algorithm>

#include "core/errors.h"

namespace handlabel {

HandEvaluator::HandEvaluator(const HandModel& model, const HandEvaluatorOptions& options)
    : options_(options),
      num_vertices_(model.num_vertices()),
      parents_(model.parents),
      tip_vertex_ids_(model.tip_vertex_ids) {
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
