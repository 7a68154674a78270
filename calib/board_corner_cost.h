#pragma once
// Reprojection residual of one board corner, for Ceres:
//   uv = project(intrinsics, cam_from_world * world_from_board * corner_in_board)
//   residual = uv - observed (pixels).
// Parameter blocks: intrinsics (NumCameraParams(model)), cam_from_world rotation
// (Eigen quaternion x, y, z, w) and translation, world_from_board rotation and
// translation.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "geometry/camera_models.h"

namespace handlabel {

class BoardCornerCost {
 public:
  BoardCornerCost(CameraModelId model, const Eigen::Vector3d& corner_in_board,
                  const Eigen::Vector2d& observed)
      : model_(model), corner_(corner_in_board), observed_(observed) {}

  template <typename T>
  bool operator()(const T* intrinsics, const T* cam_q, const T* cam_t, const T* board_q,
                  const T* board_t, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> cam_from_world(cam_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> cam_translation(cam_t);
    const Eigen::Map<const Eigen::Quaternion<T>> world_from_board(board_q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> board_translation(board_t);
    const Eigen::Matrix<T, 3, 1> in_world =
        world_from_board * corner_.cast<T>() + board_translation;
    const Eigen::Matrix<T, 3, 1> in_cam = cam_from_world * in_world + cam_translation;
    T uv[2];
    if (!ProjectToImage(model_, intrinsics, in_cam.data(), uv)) return false;
    residual[0] = uv[0] - T(observed_.x());
    residual[1] = uv[1] - T(observed_.y());
    return true;
  }

  static ceres::CostFunction* Create(CameraModelId model, const Eigen::Vector3d& corner,
                                     const Eigen::Vector2d& observed) {
    auto* cost = new BoardCornerCost(model, corner, observed);
    switch (NumCameraParams(model)) {
      case 3:
        return new ceres::AutoDiffCostFunction<BoardCornerCost, 2, 3, 4, 3, 4, 3>(cost);
      case 4:
        return new ceres::AutoDiffCostFunction<BoardCornerCost, 2, 4, 4, 3, 4, 3>(cost);
      case 5:
        return new ceres::AutoDiffCostFunction<BoardCornerCost, 2, 5, 4, 3, 4, 3>(cost);
      case 8:
        return new ceres::AutoDiffCostFunction<BoardCornerCost, 2, 8, 4, 3, 4, 3>(cost);
      default:
        return new ceres::AutoDiffCostFunction<BoardCornerCost, 2, 12, 4, 3, 4, 3>(cost);
    }
  }

 private:
  CameraModelId model_;
  Eigen::Vector3d corner_;
  Eigen::Vector2d observed_;
};

}  // namespace handlabel
