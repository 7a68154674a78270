#pragma once
// Confidence-weighted robust reprojection of the 21 hand keypoints into every view.
// One residual block holds all views so the hand's forward pass runs once per
// evaluation; residual (view v, keypoint k, axis c) at index 42 v + 2 k + c is
//   r = f(|e|^2) e,   e = sqrt(confidence) / sigma_px * (project(cam_from_world * X_k) -
//   uv)
// with the robust factor f of robust_loss.h applied per keypoint (outliers in one view
// do not down-weight the others). Projection includes lens distortion
// (geometry/camera_models.h). Keypoints behind a camera give zero residuals.
//
// Parameter blocks: global_orient (3), hand_pose (kPoseDim), betas (kNumBetas),
// transl (3), as HandEvaluator reads them.
//   MultiViewKeypointCost<...>::Create  autodiff (ceres::Jet) on the templated functor
//   MultiViewKeypointCostFunction       analytic Jacobian (HandEvaluator::
//                                       KeypointsAndJacobian); several times faster,
//                                       any pose_dim / betas count; checked against the
//                                       autodiff one in tests.
//   MultiViewKeypointSquareRootCost     the analytic one in square-root form (what the
//                                       fitter uses): same cost, gradient and
//                                       Gauss-Newton matrix in num_params + 1 rows;
//                                       the priors may be folded into it; with a
//                                       DetectorKeypointModel it compares the
//                                       detector's keypoints of the hand
//                                       (hand/detector_keypoints.h) instead of the
//                                       model's own.

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "fitting/folded_terms.h"
#include "fitting/keypoint_view.h"
#include "fitting/point_term_normal_equations.h"
#include "fitting/robust_loss.h"
#include "geometry/camera_models.h"
#include "hand/detector_keypoints.h"
#include "hand/hand_evaluator.h"

namespace handlabel {

// Per-view constants in the layout the functors read.
struct KeypointViewData {
  CameraModelId model = CameraModelId::kPinhole;
  double intrinsics[12] = {};
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> rotation;  // cam_from_world
  Eigen::Vector3d translation;
  KeypointPixels uv_px;
  KeypointConfidences weight;  // sqrt(confidence) / sigma_px
  Camera camera;               // for the analytic projection Jacobian
};

inline std::vector<KeypointViewData> MakeKeypointViewData(
    const std::vector<KeypointView>& views, double sigma_px) {
  std::vector<KeypointViewData> out(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    const Camera& cam = views[v].camera.camera;
    out[v].model = cam.model();
    for (size_t i = 0; i < cam.params().size(); ++i)
      out[v].intrinsics[i] = cam.params()[i];
    out[v].rotation = views[v].camera.cam_from_world.rotation.toRotationMatrix();
    out[v].translation = views[v].camera.cam_from_world.translation;
    out[v].uv_px = views[v].keypoints.uv_px;
    out[v].weight = views[v].keypoints.confidence.cwiseMax(0.0).cwiseSqrt() / sigma_px;
    out[v].camera = cam;
  }
  return out;
}

template <int kPoseDim = kNumPoseParams, int kNumBetas = 10>
class MultiViewKeypointCost {
 public:
  // `evaluator` must outlive the functor; `views` are copied.
  MultiViewKeypointCost(const HandEvaluator& evaluator,
                        const std::vector<KeypointView>& views, const RobustLoss& loss,
                        double sigma_px)
      : evaluator_(evaluator),
        views_(MakeKeypointViewData(views, sigma_px)),
        loss_(loss) {
    HL_CHECK(evaluator.pose_dim() == kPoseDim && evaluator.num_betas() == kNumBetas,
             "functor sizes differ from the evaluator's");
  }

  int num_residuals() const {
    return 2 * kNumHandKeypoints * static_cast<int>(views_.size());
  }

  template <typename T>
  bool operator()(const T* orient, const T* pose, const T* betas, const T* transl,
                  T* residuals) const {
    T keypoints[3 * kNumHandKeypoints];
    evaluator_.Keypoints(orient, pose, betas, transl, keypoints);
    for (size_t v = 0; v < views_.size(); ++v) {
      const KeypointViewData& view = views_[v];
      T intrinsics[12];
      for (int i = 0; i < 12; ++i) intrinsics[i] = T(view.intrinsics[i]);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        T* r = residuals + 2 * (kNumHandKeypoints * v + k);
        r[0] = T(0.0);
        r[1] = T(0.0);
        const double w = view.weight[k];
        if (w == 0.0) continue;
        const T* x = keypoints + 3 * k;
        T p[3];
        for (int i = 0; i < 3; ++i) {
          p[i] = T(view.translation[i]) + view.rotation(i, 0) * x[0] +
                 view.rotation(i, 1) * x[1] + view.rotation(i, 2) * x[2];
        }
        T uv[2];
        if (!ProjectToImage(view.model, intrinsics, p, uv)) continue;
        const T e0 = w * (uv[0] - view.uv_px(k, 0));
        const T e1 = w * (uv[1] - view.uv_px(k, 1));
        const T f = RobustFactor(loss_, e0 * e0 + e1 * e1);
        r[0] = f * e0;
        r[1] = f * e1;
      }
    }
    return true;
  }

  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const std::vector<KeypointView>& views,
                                     const RobustLoss& loss, double sigma_px) {
    auto* functor = new MultiViewKeypointCost(evaluator, views, loss, sigma_px);
    return new ceres::AutoDiffCostFunction<MultiViewKeypointCost, ceres::DYNAMIC, 3,
                                           kPoseDim, kNumBetas, 3>(
        functor, functor->num_residuals());
  }

 private:
  const HandEvaluator& evaluator_;
  std::vector<KeypointViewData> views_;
  RobustLoss loss_;
};

// The two residuals of keypoint k (position x, world frame) in one view and, when
// `d_x` is given, their derivative by x (2 x 3). False (residuals zero) when the
// keypoint has no weight or lies behind the camera.
inline bool KeypointResiduals(const KeypointViewData& view, const RobustLoss& loss, int k,
                              const double* x, double r[2],
                              Eigen::Matrix<double, 2, 3>* d_x) {
  r[0] = r[1] = 0.0;
  const double w = view.weight[k];
  if (w == 0.0) return false;
  const Eigen::Vector3d p =
      view.rotation * Eigen::Map<const Eigen::Vector3d>(x) + view.translation;
  Eigen::Vector2d uv;
  Eigen::Matrix<double, 2, 3> d_point;
  if (!view.camera.ProjectWithJacobian(p, &uv, d_x ? &d_point : nullptr)) return false;
  const Eigen::Vector2d e = w * (uv - view.uv_px.row(k).transpose());
  double f = 1.0, df = 0.0;
  RobustFactorAndDerivative(loss, e.squaredNorm(), &f, &df);
  r[0] = f * e[0];
  r[1] = f * e[1];
  if (d_x != nullptr) {
    // d r / d x = (f I + 2 f' e e^T) * w * d_uv/d_point * R.
    const Eigen::Matrix2d robust =
        f * Eigen::Matrix2d::Identity() + 2.0 * df * e * e.transpose();
    d_x->noalias() = (w * robust * d_point) * view.rotation;
  }
  return true;
}

// Same residuals with the analytic Jacobian, one row per residual (the reference for
// MultiViewKeypointSquareRootCost). Betas block size = evaluator.num_betas().
class MultiViewKeypointCostFunction : public ceres::CostFunction {
 public:
  MultiViewKeypointCostFunction(const HandEvaluator& evaluator,
                                const std::vector<KeypointView>& views,
                                const RobustLoss& loss, double sigma_px)
      : evaluator_(evaluator),
        views_(MakeKeypointViewData(views, sigma_px)),
        loss_(loss) {
    set_num_residuals(2 * kNumHandKeypoints * static_cast<int>(views_.size()));
    mutable_parameter_block_sizes()->assign(
        {3, evaluator.pose_dim(), evaluator.num_betas(), 3});
  }
  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const std::vector<KeypointView>& views,
                                     const RobustLoss& loss, double sigma_px) {
    return new MultiViewKeypointCostFunction(evaluator, views, loss, sigma_px);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int num_params = evaluator_.num_params();
    const int pose_dim = evaluator_.pose_dim(), nb = evaluator_.num_betas();
    double keypoints[3 * kNumHandKeypoints];
    thread_local std::vector<double> kp_jac;
    const bool want_jac = jacobians != nullptr;
    if (want_jac) {
      kp_jac.resize(3 * kNumHandKeypoints * num_params);
      evaluator_.KeypointsAndJacobian(parameters[0], parameters[1], parameters[2],
                                      parameters[3], keypoints, kp_jac.data());
    } else {
      evaluator_.Keypoints(parameters[0], parameters[1], parameters[2], parameters[3],
                           keypoints);
    }
    const int block_offset[4] = {0, 3, 3 + pose_dim, 3 + pose_dim + nb};
    const int block_size[4] = {3, pose_dim, nb, 3};
    Eigen::Matrix<double, 2, Eigen::Dynamic> row_jac(2, num_params);
    for (size_t v = 0; v < views_.size(); ++v) {
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        const int row = 2 * (kNumHandKeypoints * static_cast<int>(v) + k);
        Eigen::Matrix<double, 2, 3> d_x;
        const bool valid = KeypointResiduals(views_[v], loss_, k, keypoints + 3 * k,
                                             residuals + row, want_jac ? &d_x : nullptr);
        if (!want_jac) continue;
        if (valid) {
          const Eigen::Map<
              const Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>>
              dx(kp_jac.data() + 3 * k * num_params, 3, num_params);
          row_jac.noalias() = d_x * dx;
        } else {
          row_jac.setZero();
        }
        for (int b = 0; b < 4; ++b) {
          if (jacobians[b] == nullptr) continue;
          for (int i = 0; i < 2; ++i) {
            for (int c = 0; c < block_size[b]; ++c) {
              jacobians[b][(row + i) * block_size[b] + c] =
                  row_jac(i, block_offset[b] + c);
            }
          }
        }
      }
    }
    return true;
  }

 private:
  const HandEvaluator& evaluator_;
  std::vector<KeypointViewData> views_;
  RobustLoss loss_;
};

// The same term in square-root form (fitting/point_term_normal_equations.h):
// num_params + 1 residuals with the same cost, gradient and Gauss-Newton matrix as
// MultiViewKeypointCostFunction, which Ceres' linear algebra handles several times
// faster than its 42 rows per view. What the fitter uses.
class MultiViewKeypointSquareRootCost : public ceres::CostFunction {
 public:
  // `detector` (may be nullptr: the model's keypoints) must outlive the cost.
  MultiViewKeypointSquareRootCost(const HandEvaluator& evaluator,
                                  const std::vector<KeypointView>& views,
                                  const RobustLoss& loss, double sigma_px,
                                  const DetectorKeypointModel* detector = nullptr)
      : evaluator_(evaluator),
        views_(MakeKeypointViewData(views, sigma_px)),
        loss_(loss),
        detector_(detector),
        detector_vertices_(detector ? detector->AllVertexIds() : std::vector<int>()),
        block_sizes_({3, evaluator.pose_dim(), evaluator.num_betas(), 3}),
        folded_(block_sizes_) {
    set_num_residuals(evaluator.num_params() + 1);
    mutable_parameter_block_sizes()->assign(block_sizes_.begin(), block_sizes_.end());
  }
  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const std::vector<KeypointView>& views,
                                     const RobustLoss& loss, double sigma_px) {
    return new MultiViewKeypointSquareRootCost(evaluator, views, loss, sigma_px);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = evaluator_.num_params();
    double keypoints[3 * kNumHandKeypoints];
    thread_local std::vector<double> kp_jac;
    if (jacobians == nullptr) {
      if (detector_) {
        DetectorKeypoints(evaluator_, *detector_, detector_vertices_, parameters[0],
                          parameters[1], parameters[2], parameters[3], keypoints);
      } else {
        evaluator_.Keypoints(parameters[0], parameters[1], parameters[2], parameters[3],
                             keypoints);
      }
      double squared_norm = 0.0;
      for (const KeypointViewData& view : views_) {
        for (int k = 0; k < kNumHandKeypoints; ++k) {
          double r[2];
          KeypointResiduals(view, loss_, k, keypoints + 3 * k, r, nullptr);
          squared_norm += r[0] * r[0] + r[1] * r[1];
        }
      }
      WriteCostOnly(squared_norm + folded_.SquaredNorm(parameters), n + 1, residuals);
      return true;
    }
    kp_jac.resize(3 * kNumHandKeypoints * n);
    if (detector_) {
      DetectorKeypointsAndJacobian(evaluator_, *detector_, detector_vertices_,
                                   parameters[0], parameters[1], parameters[2],
                                   parameters[3], keypoints, kp_jac.data());
    } else {
      evaluator_.KeypointsAndJacobian(parameters[0], parameters[1], parameters[2],
                                      parameters[3], keypoints, kp_jac.data());
    }
    PointTermNormalEquations normal(kNumHandKeypoints);
    for (const KeypointViewData& view : views_) {
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        double r[2];
        Eigen::Matrix<double, 2, 3> d_x;
        if (KeypointResiduals(view, loss_, k, keypoints + 3 * k, r, &d_x)) {
          normal.AddRow(k, r[0], d_x.row(0).transpose());
          normal.AddRow(k, r[1], d_x.row(1).transpose());
        }
      }
    }
    // Jacobian blocks of the used keypoints, in UsedPoints() order.
    const std::vector<int> used = normal.UsedPoints();
    thread_local std::vector<double> used_jac;
    used_jac.resize(3 * used.size() * n);
    for (size_t i = 0; i < used.size(); ++i) {
      std::copy_n(kp_jac.data() + 3 * used[i] * n, 3 * n, used_jac.data() + 3 * i * n);
    }
    Eigen::MatrixXd jtj;
    Eigen::VectorXd jtr;
    normal.Accumulate(used_jac.data(), n, &jtj, &jtr);
    double squared_norm = normal.squared_norm();
    folded_.AddNormalEquations(parameters, &jtj, &jtr, &squared_norm);
    WriteSquareRootForm(jtj, jtr, squared_norm, block_sizes_, residuals, jacobians);
    return true;
  }

  // Terms on one of this cost's blocks evaluated inside it (folded_terms.h).
  FoldedTerms* folded() { return &folded_; }
  const FoldedTerms& folded() const { return folded_; }

 private:
  const HandEvaluator& evaluator_;
  std::vector<KeypointViewData> views_;
  RobustLoss loss_;
  const DetectorKeypointModel* detector_;
  std::vector<int> detector_vertices_;
  std::vector<int> block_sizes_;
  FoldedTerms folded_;
};

}  // namespace handlabel
