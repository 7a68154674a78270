#include "hand/hand_model.h"

#include "core/errors.h"

namespace handlabel {
namespace {

std::string Shape(Eigen::Index rows, Eigen::Index cols) {
  return "(" + std::to_string(rows) + ", " + std::to_string(cols) + ")";
}

void ExpectShape(const std::string& source, const char* field, Eigen::Index rows,
                 Eigen::Index cols, Eigen::Index want_rows, Eigen::Index want_cols) {
  if (rows != want_rows || cols != want_cols) {
    throw InputError(source, field, "shape " + Shape(want_rows, want_cols),
                     Shape(rows, cols));
  }
}

}  // namespace

std::string HandSideName(HandSide side) {
  return side == HandSide::kLeft ? "left" : "right";
}

std::optional<HandSide> HandSideFromName(const std::string& name) {
  for (const HandSide side : {HandSide::kRight, HandSide::kLeft}) {
    if (name == HandSideName(side)) return side;
  }
  return std::nullopt;
}

HandSide ParseHandSide(const std::string& text, const std::string& source,
                       const std::string& field) {
  const std::optional<HandSide> side = HandSideFromName(text);
  if (!side) throw InputError(source, field, "\"right\" or \"left\"", text);
  return *side;
}

void HandModel::Check(const std::string& source) const {
  const Eigen::Index v = v_template.rows();
  if (v < 4)
    throw InputError(source, "v_template", "at least 4 vertices", std::to_string(v));
  ExpectShape(source, "shapedirs", shapedirs.rows(), shapedirs.cols(), 3 * v,
              shapedirs.cols());
  ExpectShape(source, "posedirs", posedirs.rows(), posedirs.cols(), 3 * v,
              9 * (kNumHandJoints - 1));
  ExpectShape(source, "J_regressor", joint_regressor.rows(), joint_regressor.cols(),
              kNumHandJoints, v);
  ExpectShape(source, "weights", skinning_weights.rows(), skinning_weights.cols(), v,
              kNumHandJoints);
  if (faces.rows() < 1) throw InputError(source, "f", "at least one face", "none");
  if (faces.minCoeff() < 0 || faces.maxCoeff() >= v) {
    throw InputError(source, "f", "vertex indices in [0, " + std::to_string(v) + ")",
                     "[" + std::to_string(faces.minCoeff()) + ", " +
                         std::to_string(faces.maxCoeff()) + "]");
  }
  for (int t : tip_vertex_ids) {
    if (t < 0 || t >= v) {
      throw InputError(source, "tip_vertex_ids", "vertex ids below " + std::to_string(v),
                       std::to_string(t));
    }
  }
  if (parents[0] != -1) throw InputError(source, "kintree_table", "root parent -1");
  for (int j = 1; j < kNumHandJoints; ++j) {
    if (parents[j] < 0 || parents[j] >= j) {
      throw InputError(
          source, "kintree_table", "parents that precede their children (MANO's tree)",
          "joint " + std::to_string(j) + " -> " + std::to_string(parents[j]));
    }
  }
  if (pose_pca_basis.size() != 0) {
    ExpectShape(source, "hands_components", pose_pca_basis.rows(), pose_pca_basis.cols(),
                pose_pca_basis.rows(), kNumPoseParams);
  }
  if (pose_mean.size() != 0 && pose_mean.size() != kNumPoseParams) {
    throw InputError(source, "hands_mean", "45 values", std::to_string(pose_mean.size()));
  }
  if (!v_template.allFinite() || !shapedirs.allFinite() || !posedirs.allFinite() ||
      !skinning_weights.allFinite()) {
    throw InputError(source, "arrays", "finite values", "NaN or inf");
  }
}

}  // namespace handlabel
