#pragma once
// Confidence-weighted robust reprojection of the 21 hand keypoints into every view.
// One residual block holds all views so the hand's forward pass runs once per
// evaluation; residual (view v, keypoint k, axis c) at index 42 v + 2 k + c is
//   r = f(|e|^2) e,   e = sqrt(confidence) / sigma_px * (project(cam_from_world * X_k) -
//   uv)
// with the robust factor f of robust_loss.h applied per keypoint (outliers in one view
// do not down-weight the others). Projection includes lens distortion
// (core/camera_models.h). Keypoints behind a camera give zero residuals.
//
// Parameter blocks: global_orient (3), hand_pose (kPoseDim), betas (kNumBetas),
// transl (3), as HandEvaluator reads them.
//   MultiViewKeypointCost<...>::Create  autodiff (ceres::Jet) on the templated functor
//   MultiViewKeypointCostFunction       analytic Jacobian (HandEvaluator::
//                                       KeypointsAndJacobian); several times faster,
//                                       any pose_dim / betas count; checked against the
//                                       autodiff one in tests.

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

#include "core/camera_models.h"
#include "core/hand_evaluator.h"
#include "fitting/keypoint_view.h"
#include "fitting/robust_loss.h"

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

// Same residuals with the analytic Jacobian. Betas block size = evaluator.num_betas().
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
      const KeypointViewData& view = views_[v];
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        const int row = 2 * (kNumHandKeypoints * static_cast<int>(v) + k);
        double* r = residuals + row;
        r[0] = r[1] = 0.0;
        const double w = view.weight[k];
        bool valid = w != 0.0;
        Eigen::Vector2d uv;
        Eigen::Matrix<double, 2, 3> d_point;
        if (valid) {
          const Eigen::Vector3d p =
              view.rotation * Eigen::Map<const Eigen::Vector3d>(keypoints + 3 * k) +
              view.translation;
          valid = view.camera.ProjectWithJacobian(p, &uv, want_jac ? &d_point : nullptr);
        }
        double f = 1.0, df = 0.0;
        Eigen::Vector2d e = Eigen::Vector2d::Zero();
        if (valid) {
          e = w * (uv - view.uv_px.row(k).transpose());
          RobustFactorAndDerivative(loss_, e.squaredNorm(), &f, &df);
          r[0] = f * e[0];
          r[1] = f * e[1];
        }
        if (!want_jac) continue;
        if (valid) {
          // d r / d params = (f I + 2 f' e e^T) * w * d_uv/d_point * R * d X_k / d
          // params.
          const Eigen::Matrix2d robust =
              f * Eigen::Matrix2d::Identity() + 2.0 * df * e * e.transpose();
          const Eigen::Matrix<double, 2, 3> a = w * robust * d_point * view.rotation;
          const Eigen::Map<
              const Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>>
              dx(kp_jac.data() + 3 * k * num_params, 3, num_params);
          row_jac.noalias() = a * dx;
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

}  // namespace handlabel
