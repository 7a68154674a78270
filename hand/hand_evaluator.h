#pragma once
// HandEvaluator: the MANO forward pass (same semantics as PoseHand in hand_lbs.h)
// templated on the scalar type, for ceres::Jet (autodiff in fitting), core's Dual
// (Jacobians inside core) and double. Built once per model; it precomputes
//   - rest joints as a linear function of betas: J(b) = J_regressor * v_template +
//     (J_regressor * shapedirs) * b, so joints never touch the mesh;
//   - row-major per-vertex blend shapes and sparse skinning weights, so any subset of
//     vertices (e.g. the 5 fingertips of the keypoint path) costs only its own rows.
//
// Parameter arrays (all raw pointers, so Ceres parameter blocks can be passed as is):
//   global_orient  3            root axis-angle; the root rotates about rest joint 0
//   hand_pose      pose_dim()   45 axis-angle values of the 15 non-root joints (native
//                               order), or num_pca_comps PCA coefficients (options)
//   betas          num_betas()  may be nullptr (= zeros)
//   transl         3            added last; may be nullptr (= zeros)
// Outputs are row-major point arrays (x, y, z per point) in the model's frame.
//
// Typical use (fitting): a cost functor holds `const HandEvaluator&` and calls
//   evaluator.Keypoints(orient, pose, betas, transl, keypoints63);
// For keypoints and a vertex subset in one pass, call Pose() once and then
// KeypointsFromState() / VerticesFromState() on the same state. For analytic Ceres
// cost functions, KeypointsAndJacobian() returns keypoints and their Jacobian in
// doubles, several times faster than Jets. Usage and timings: docs/hand-model.md.
//
// Scalar requirements: double, or a first-order dual type with public members `a`
// (value) and `v` (Eigen derivative vector) supporting T(double), + - * / with T and
// double, comparison, and sqrt/sin/cos by ADL (Dual<N>, ceres::Jet<double, N>).

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "core/errors.h"
#include "geometry/axis_angle.h"
#include "geometry/dual.h"
#include "geometry/scalar_ops.h"
#include "hand/hand_model.h"

namespace handlabel {

struct HandEvaluatorOptions {
  // Length of the betas arrays the evaluator reads (the first n shape coefficients of
  // the model); -1 = all of the model's.
  int num_betas = -1;
  // 0: hand_pose is 45 axis-angle values. n > 0: hand_pose is n PCA coefficients,
  // pose = coeffs * pose_pca_basis[:n] (+ pose_mean unless flat_hand_mean).
  int num_pca_comps = 0;
  // PCA mode only: do not add the model's pose_mean (MANO's flat_hand_mean).
  bool flat_hand_mean = false;
  // Model-independent checks (the evaluator's constructor also checks against the
  // model); throws InputError.
  void Check(const std::string& source) const;
};

// Most shape coefficients an evaluator reads (MANO has 10).
constexpr int kMaxHandBetas = 32;

// Intermediate results of one forward pass, shared by the keypoint and vertex outputs.
template <typename T>
struct HandPoseState {
  static constexpr bool kIsDouble = std::is_same_v<T, double>;
  T rest_joints[kNumHandJoints * 3];  // J(betas), native order
  T world[kNumHandJoints * 12];       // G_j as row-major [R | t]; t = posed joint
  T skin_t[kNumHandJoints * 3];       // translation of G_j * [I | -J_j]
  T transl[3];
  // Pose blend shapes. T = double: pose_feature = vec(R_j - I), j = 1..15.
  // Dual/Jet types: v_posed is linear in betas and, per joint, a function of that
  // joint's 3 axis-angle values only, so it is evaluated in doubles and its derivative
  // enters through the chain rule (first order is exact for these types):
  //   v_posed = value + shapedirs * betas_delta
  //             + sum_j (posedirs_j * d vec(R_j) / d w_j) * w_delta_j
  // which costs 55 instead of 145 dual multiply-adds per vertex coordinate.
  // Arrays a path does not use have size 1: dual types zero-initialise, so unused
  // storage would cost time on every call.
  T pose_feature[kIsDouble ? 9 * (kNumHandJoints - 1) : 1];  // double path
  T betas[kIsDouble ? kMaxHandBetas : 1];                    // double path
  double feature_value[9 * (kNumHandJoints - 1)];            // dual: vec(R_j - I)
  double feature_jac[9 * (kNumHandJoints - 1)][3];           // dual: d feature / d w_j
  double betas_value[kMaxHandBetas];                         // dual
  T betas_delta[kIsDouble ? 1 : kMaxHandBetas];  // dual: betas - value (derivatives)
  T pose_delta[kIsDouble ? 1 : kNumPoseParams];  // dual: axis-angle pose - value
};

class HandEvaluator {
 public:
  // Copies what it needs from `model` (which may be destroyed afterwards). Throws
  // InputError if the options do not fit the model (too many betas, PCA without basis).
  explicit HandEvaluator(const HandModel& model,
                         const HandEvaluatorOptions& options = {});

  int num_vertices() const { return num_vertices_; }
  int num_betas() const { return num_betas_; }
  // Length of the hand_pose arrays: 45, or the number of PCA coefficients.
  int pose_dim() const {
    return options_.num_pca_comps > 0 ? options_.num_pca_comps : 45;
  }
  const HandEvaluatorOptions& options() const { return options_; }
  const std::array<int, 5>& tip_vertex_ids() const { return tip_vertex_ids_; }

  // 45 axis-angle values from hand_pose (identity copy unless in PCA mode).
  template <typename T>
  void AxisAnglePose(const T* hand_pose, T* pose45) const;

  // Rest joints J(betas), 16 x 3.
  template <typename T>
  void RestJoints(const T* betas, T* joints48) const;

  // Everything up to skinning.
  template <typename T>
  void Pose(const T* global_orient, const T* hand_pose, const T* betas, const T* transl,
            HandPoseState<T>* state) const;

  // 16 posed joints (native order) + transl.
  template <typename T>
  void JointsFromState(const HandPoseState<T>& state, T* joints48) const;
  // 21 keypoints in SNAP order (16 joints + the model's 5 tip vertices).
  template <typename T>
  void KeypointsFromState(const HandPoseState<T>& state, T* keypoints63) const;
  // Posed vertices `ids` (any order, repeats allowed) into out[3 * i + c].
  template <typename T>
  void VerticesFromState(const HandPoseState<T>& state, const std::vector<int>& ids,
                         T* out) const;
  // All vertices into out[3 * v + c].
  template <typename T>
  void AllVerticesFromState(const HandPoseState<T>& state, T* out) const;

  // Parameters of the Jacobian below: 3 + pose_dim() + num_betas() + 3.
  int num_params() const { return 3 + pose_dim() + num_betas_ + 3; }

  // 21 keypoints (SNAP order) and their analytic Jacobian, doubles only: `jacobian`
  // is row-major 63 x num_params(), columns (global_orient, hand_pose, betas, transl).
  // Several times cheaper than dual numbers because it uses the kinematic structure
  // (a joint's rotation moves only its subtree); for analytic Ceres cost functions.
  // betas / transl may be nullptr (zeros; their columns are still filled).
  void KeypointsAndJacobian(const double* global_orient, const double* hand_pose,
                            const double* betas, const double* transl,
                            double* keypoints63, double* jacobian) const;

  // Posed vertices `ids` (as VerticesFromState) and their analytic Jacobian, doubles
  // only: `jacobian` is row-major (3 ids.size()) x num_params(), columns as in
  // KeypointsAndJacobian. Several times cheaper than ceres::Jet over all parameters.
  void VerticesAndJacobian(const double* global_orient, const double* hand_pose,
                           const double* betas, const double* transl,
                           const std::vector<int>& ids, double* out,
                           double* jacobian) const;

  // One-call conveniences.
  template <typename T>
  void Keypoints(const T* global_orient, const T* hand_pose, const T* betas,
                 const T* transl, T* keypoints63) const {
    HandPoseState<T> state;
    Pose(global_orient, hand_pose, betas, transl, &state);
    KeypointsFromState(state, keypoints63);
  }
  template <typename T>
  void Joints(const T* global_orient, const T* hand_pose, const T* betas, const T* transl,
              T* joints48) const {
    HandPoseState<T> state;
    Pose(global_orient, hand_pose, betas, transl, &state);
    JointsFromState(state, joints48);
  }
  template <typename T>
  void Vertices(const T* global_orient, const T* hand_pose, const T* betas,
                const T* transl, const std::vector<int>& ids, T* out) const {
    HandPoseState<T> state;
    Pose(global_orient, hand_pose, betas, transl, &state);
    VerticesFromState(state, ids, out);
  }
  template <typename T>
  void AllVertices(const T* global_orient, const T* hand_pose, const T* betas,
                   const T* transl, T* out) const {
    HandPoseState<T> state;
    Pose(global_orient, hand_pose, betas, transl, &state);
    AllVerticesFromState(state, out);
  }

 private:
  template <typename T>
  void SkinVertex(const HandPoseState<T>& state, int v, T* out) const;

  // The analytic Jacobians' shared forward pass (hand_evaluator.cc) and the writing of
  // one point's 3 rows (axis-angle pose columns mapped to PCA where used).
  struct JacobianPass;
  void PrepareJacobian(const double* global_orient, const double* hand_pose,
                       const double* betas, const double* transl,
                       JacobianPass* pass) const;
  void WriteJacobianRows(const Eigen::Matrix3d& d_orient,
                         const Eigen::Matrix<double, 3, kNumPoseParams>& d_pose,
                         const Eigen::Matrix<double, 3, Eigen::Dynamic>& d_shape,
                         double* rows) const;

  using RowMatrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  HandEvaluatorOptions options_;
  int num_vertices_ = 0;
  int num_betas_ = 0;
  std::array<int, kNumHandJoints> parents_{};
  std::array<int, 5> tip_vertex_ids_{};
  Eigen::Matrix<double, 3 * kNumHandJoints, 1>
      joint_template_;          // J_regressor * v_template
  RowMatrix joint_shapedirs_;   // 48 x num_betas: J_regressor * shapedirs
  Eigen::VectorXd v_template_;  // 3V
  RowMatrix shapedirs_;         // 3V x num_betas
  RowMatrix posedirs_;          // 3V x 135
  // Sparse skinning weights (exact zeros dropped): vertex v uses entries
  // weight_start_[v] .. weight_start_[v + 1] - 1.
  std::vector<int> weight_start_;
  std::vector<int> weight_joint_;
  std::vector<double> weight_value_;
  RowMatrix pca_basis_;  // num_pca_comps x 45
  Eigen::Matrix<double, 45, 1> pca_mean_ = Eigen::Matrix<double, 45, 1>::Zero();
};

// ---------------------------------------------------------------------------------
// Template definitions.

template <typename T>
void HandEvaluator::AxisAnglePose(const T* hand_pose, T* pose45) const {
  const int n = options_.num_pca_comps;
  if (n == 0) {
    for (int i = 0; i < 45; ++i) pose45[i] = hand_pose[i];
    return;
  }
  for (int i = 0; i < 45; ++i) {
    T sum = T(pca_mean_[i]);
    for (int k = 0; k < n; ++k) AddScaled(pca_basis_(k, i), hand_pose[k], &sum);
    pose45[i] = sum;
  }
}

template <typename T>
void HandEvaluator::RestJoints(const T* betas, T* joints48) const {
  for (int i = 0; i < 3 * kNumHandJoints; ++i) {
    T sum = T(joint_template_[i]);
    if (betas != nullptr) {
      for (int s = 0; s < num_betas_; ++s) {
        AddScaled(joint_shapedirs_(i, s), betas[s], &sum);
      }
    }
    joints48[i] = sum;
  }
}

template <typename T>
void HandEvaluator::Pose(const T* global_orient, const T* hand_pose, const T* betas,
                         const T* transl, HandPoseState<T>* state) const {
  RestJoints(betas, state->rest_joints);
  for (int s = 0; s < num_betas_; ++s) {
    if constexpr (HandPoseState<T>::kIsDouble) {
      state->betas[s] = betas ? betas[s] : 0.0;
    } else if (betas) {
      state->betas_value[s] = ScalarPart(betas[s]);
      state->betas_delta[s] = betas[s] - state->betas_value[s];
    } else {
      state->betas_value[s] = 0.0;
      state->betas_delta[s] = T(0.0);
    }
  }
  // Axis-angle pose: the caller's array, or its PCA expansion.
  std::vector<T> pca_pose;
  const T* pose45 = hand_pose;
  if (options_.num_pca_comps > 0) {
    pca_pose.resize(kNumPoseParams);
    AxisAnglePose(hand_pose, pca_pose.data());
    pose45 = pca_pose.data();
  }
  for (int c = 0; c < 3; ++c) state->transl[c] = transl ? transl[c] : T(0.0);
  for (int j = 0; j < kNumHandJoints; ++j) {
    T local[9];
    AxisAngleToRotation(j == 0 ? global_orient : pose45 + 3 * (j - 1), local);
    if (j > 0) {
      if constexpr (HandPoseState<T>::kIsDouble) {
        T* feature = state->pose_feature + 9 * (j - 1);
        for (int i = 0; i < 9; ++i) feature[i] = local[i];
        feature[0] -= 1.0;
        feature[4] -= 1.0;
        feature[8] -= 1.0;
      } else {
        // Value and 9x3 Jacobian of vec(R_j) w.r.t. the joint's own axis-angle.
        Dual<3> w[3], r[9];
        for (int i = 0; i < 3; ++i) {
          const double value = ScalarPart(pose45[3 * (j - 1) + i]);
          w[i] = Dual<3>(value, i);
          state->pose_delta[3 * (j - 1) + i] = pose45[3 * (j - 1) + i] - value;
        }
        AxisAngleToRotation(w, r);
        for (int e = 0; e < 9; ++e) {
          const int k = 9 * (j - 1) + e;
          state->feature_value[k] = r[e].a - (e % 4 == 0 ? 1.0 : 0.0);
          for (int i = 0; i < 3; ++i) state->feature_jac[k][i] = r[e].v[i];
        }
      }
    }
    const T* rest = state->rest_joints + 3 * j;
    T* g = state->world + 12 * j;
    const int parent = parents_[j];
    if (parent < 0) {
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) g[4 * r + c] = local[3 * r + c];
        g[4 * r + 3] = rest[r];
      }
    } else {
      const T* gp = state->world + 12 * parent;
      const T* rest_parent = state->rest_joints + 3 * parent;
      T offset[3] = {rest[0] - rest_parent[0], rest[1] - rest_parent[1],
                     rest[2] - rest_parent[2]};
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          g[4 * r + c] = Dot3(gp + 4 * r, 1, local + c, 3, T(0.0));
        }
        g[4 * r + 3] = Dot3(gp + 4 * r, 1, offset, 1, gp[4 * r + 3]);
      }
    }
    for (int r = 0; r < 3; ++r) {
      state->skin_t[3 * j + r] = g[4 * r + 3] - Dot3(g + 4 * r, 1, rest, 1, T(0.0));
    }
  }
}

template <typename T>
void HandEvaluator::JointsFromState(const HandPoseState<T>& state, T* joints48) const {
  for (int j = 0; j < kNumHandJoints; ++j) {
    for (int c = 0; c < 3; ++c) {
      joints48[3 * j + c] = state.world[12 * j + 4 * c + 3] + state.transl[c];
    }
  }
}

template <typename T>
void HandEvaluator::KeypointsFromState(const HandPoseState<T>& state,
                                       T* keypoints63) const {
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int native = kSnapFromNative[k];
    T* out = keypoints63 + 3 * k;
    if (native < kNumHandJoints) {
      for (int c = 0; c < 3; ++c) {
        out[c] = state.world[12 * native + 4 * c + 3] + state.transl[c];
      }
    } else {
      SkinVertex(state, tip_vertex_ids_[native - kNumHandJoints], out);
    }
  }
}

template <typename T>
void HandEvaluator::VerticesFromState(const HandPoseState<T>& state,
                                      const std::vector<int>& ids, T* out) const {
  for (size_t i = 0; i < ids.size(); ++i) {
    HL_CHECK(
        ids[i] >= 0 && ids[i] < num_vertices_,
        "vertex id " + std::to_string(ids[i]) + " of " + std::to_string(num_vertices_));
    SkinVertex(state, ids[i], out + 3 * i);
  }
}

template <typename T>
void HandEvaluator::AllVerticesFromState(const HandPoseState<T>& state, T* out) const {
  for (int v = 0; v < num_vertices_; ++v) SkinVertex(state, v, out + 3 * v);
}

template <typename T>
void HandEvaluator::SkinVertex(const HandPoseState<T>& state, int v, T* out) const {
  constexpr int kFeatures = 9 * (kNumHandJoints - 1);
  T p[3];  // v_posed
  for (int c = 0; c < 3; ++c) {
    const Eigen::Index row = 3 * v + c;
    const double* sd = shapedirs_.data() + row * num_betas_;
    const double* pd = posedirs_.data() + row * kFeatures;
    if constexpr (std::is_same_v<T, double>) {
      T sum = v_template_[row];
      for (int s = 0; s < num_betas_; ++s) sum += sd[s] * state.betas[s];
      for (int k = 0; k < kFeatures; ++k) sum += pd[k] * state.pose_feature[k];
      p[c] = sum;
    } else {
      double value = v_template_[row];
      for (int s = 0; s < num_betas_; ++s) value += sd[s] * state.betas_value[s];
      double grad[kNumPoseParams] = {};
      for (int k = 0; k < kFeatures; ++k) {
        value += pd[k] * state.feature_value[k];
        double* g = grad + 3 * (k / 9);
        g[0] += pd[k] * state.feature_jac[k][0];
        g[1] += pd[k] * state.feature_jac[k][1];
        g[2] += pd[k] * state.feature_jac[k][2];
      }
      T sum = T(value);
      for (int s = 0; s < num_betas_; ++s) AddScaled(sd[s], state.betas_delta[s], &sum);
      for (int i = 0; i < kNumPoseParams; ++i) {
        AddScaled(grad[i], state.pose_delta[i], &sum);
      }
      p[c] = sum;
    }
  }
  // Blend the 3x4 skinning transforms, then apply once.
  T m[12];
  for (T& x : m) x = T(0.0);
  for (int e = weight_start_[v]; e < weight_start_[v + 1]; ++e) {
    const int j = weight_joint_[e];
    const double w = weight_value_[e];
    const T* g = state.world + 12 * j;
    for (int r = 0; r < 3; ++r) {
      AddScaled(w, g[4 * r], &m[4 * r]);
      AddScaled(w, g[4 * r + 1], &m[4 * r + 1]);
      AddScaled(w, g[4 * r + 2], &m[4 * r + 2]);
      AddScaled(w, state.skin_t[3 * j + r], &m[4 * r + 3]);
    }
  }
  for (int r = 0; r < 3; ++r) {
    out[r] = Dot3(m + 4 * r, 1, p, 1, m[4 * r + 3] + state.transl[r]);
  }
}

}  // namespace handlabel
