#pragma once
// The hand model's data: everything a MANO-compatible linear-blend-skinning model
// needs. Loaded from MANO files (pickle / npz) or from the project's own open hand in
// models/. The forward pass lives in hand_lbs.h; loaders in hand_model_io.h.
//
// Array layouts (V vertices, S shape coefficients, J = 16 joints in native order):
//   v_template        V x 3
//   faces             F x 3 vertex indices (counter-clockwise seen from outside)
//   shapedirs         3V x S, row 3*v + c (MANO's (V,3,S) flattened row-major)
//   posedirs          3V x 135, row 3*v + c; column 9*(j-1) + 3*r + s multiplies
//                     (R_j - I)(r, s) of non-root joint j
//   joint_regressor   J x V sparse
//   skinning_weights  V x J
//   pose_pca_basis    45 x 45, row k = k-th principal component (MANO hands_components)
//   pose_mean         45 (MANO hands_mean), axis-angle of the 15 non-root joints

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <optional>
#include <string>

namespace handlabel {

enum class HandSide { kRight, kLeft };

// "right" or "left": the spelling of every file, flag and message that names a side.
std::string HandSideName(HandSide side);
// The side `name` spells (exactly "right" or "left"), or nullopt.
std::optional<HandSide> HandSideFromName(const std::string& name);
// As HandSideFromName, but anything else throws InputError(source, field, ...).
HandSide ParseHandSide(const std::string& text, const std::string& source,
                       const std::string& field);

constexpr int kNumHandJoints = 16;     // MANO native joints
constexpr int kNumHandKeypoints = 21;  // 16 joints + 5 fingertips
constexpr int kNumPoseParams = 45;     // 15 non-root joints x axis-angle

// Native joint order: 0 wrist, 1-3 index, 4-6 middle, 7-9 pinky, 10-12 ring,
// 13-15 thumb; fingertips appended as 16-20 (thumb, index, middle, ring, pinky).
// kSnapFromNative[k] = native+tips index of SNAP/OpenPose keypoint k (wrist, thumb
// CMC/MCP/IP/tip, index MCP/PIP/DIP/tip, middle, ring, pinky).
constexpr std::array<int, kNumHandKeypoints> kSnapFromNative = {
    0, 13, 14, 15, 16, 1, 2, 3, 17, 4, 5, 6, 18, 10, 11, 12, 19, 7, 8, 9, 20};
constexpr std::array<int, kNumHandJoints> kManoParents = {-1, 0, 1, 2,  0,  4, 5,  0,
                                                          7,  8, 0, 10, 11, 0, 13, 14};

struct HandModel {
  std::string name;  // e.g. "MANO_RIGHT" or "open_hand_right"
  HandSide side = HandSide::kRight;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> v_template;
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> faces;
  Eigen::MatrixXd shapedirs;
  Eigen::MatrixXd posedirs;
  Eigen::SparseMatrix<double, Eigen::RowMajor> joint_regressor;
  Eigen::Matrix<double, Eigen::Dynamic, kNumHandJoints, Eigen::RowMajor> skinning_weights;
  std::array<int, kNumHandJoints> parents = kManoParents;
  // Fingertip vertex ids (thumb, index, middle, ring, pinky): a property of the model,
  // since MANO users disagree on them (manopth [745,317,444,556,673], POEM
  // [744,320,443,555,672]).
  std::array<int, 5> tip_vertex_ids = {745, 317, 444, 556, 673};
  Eigen::MatrixXd pose_pca_basis;
  Eigen::VectorXd pose_mean;

  int num_vertices() const { return static_cast<int>(v_template.rows()); }
  int num_faces() const { return static_cast<int>(faces.rows()); }
  int num_betas() const { return static_cast<int>(shapedirs.cols()); }

  // Verifies every array's shape and index range; throws InputError naming `source`
  // and the offending field.
  void Check(const std::string& source) const;
};

}  // namespace handlabel
