#include "calib/board_scale.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "core/errors.h"
#include "geometry/triangulation.h"

namespace handlabel {
namespace {

double Median(std::vector<double> values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

}  // namespace

BoardScaleResult ScaleFromBoard(const Rig& rig,
                                const std::vector<CameraBoardViews>& views,
                                const BoardSpec& board, const std::string& source) {
  // frame -> corner id -> observations in rig cameras
  std::map<std::string, std::map<int, std::vector<ViewObservation>>> by_frame;
  std::string seen;
  for (const CameraBoardViews& camera : views) {
    const int index = rig.IndexOf(camera.name);
    if (index < 0 || camera.frames.empty()) continue;
    seen += (seen.empty() ? "" : ", ") + camera.name;
    for (const auto& [frame, observation] : camera.frames) {
      for (size_t i = 0; i < observation.size(); ++i) {
        by_frame[frame][observation.ids[i]].push_back(
            {index, observation.pixels[i], 1.0});
      }
    }
  }
  BoardScaleResult result;
  std::vector<double> ratios;
  std::vector<std::pair<int, Eigen::Vector3d>> pose_points;  // of result.board_frame
  for (const auto& [frame, corners] : by_frame) {
    std::vector<std::pair<int, Eigen::Vector3d>> points;
    for (const auto& [id, observations] : corners) {
      if (observations.size() < 2) continue;
      const RobustTriangulation t = TriangulateRobust(rig, observations);
      if (t.valid) points.emplace_back(id, t.point);
    }
    if (points.size() < 2) continue;
    if (result.board_frame.empty() && points.size() >= 3) {
      result.board_frame = frame;
      pose_points = points;
    }
    ++result.frames;
    result.corners += static_cast<int>(points.size());
    for (size_t a = 0; a < points.size(); ++a) {
      for (size_t b = a + 1; b < points.size(); ++b) {
        const double measured = (points[a].second - points[b].second).norm();
        const double truth =
            (board.Corner(points[a].first) - board.Corner(points[b].first)).norm();
        if (measured > 0) ratios.push_back(truth / measured);
      }
    }
  }
  if (ratios.empty()) {
    throw InputError(source, "board views",
                     "a frame with 2 or more board corners each seen by 2 or more rig "
                     "cameras at the same time",
                     seen.empty() ? "no detections in any camera of the rig"
                                  : "none; cameras with detections: " + seen);
  }
  result.pairs = static_cast<int>(ratios.size());
  result.scale = Median(ratios);
  std::vector<double> deviations;
  deviations.reserve(ratios.size());
  for (double r : ratios) deviations.push_back(std::abs(r - result.scale));
  result.spread = Median(deviations) / result.scale;
  if (!pose_points.empty()) {
    Eigen::Matrix3Xd on_board(3, pose_points.size()), in_world(3, pose_points.size());
    for (size_t i = 0; i < pose_points.size(); ++i) {
      on_board.col(i) = board.Corner(pose_points[i].first);
      in_world.col(i) = result.scale * pose_points[i].second;
    }
    const Eigen::Matrix4d m = Eigen::umeyama(on_board, in_world, /*with_scaling=*/false);
    result.world_from_board =
        Rigid3(Eigen::Quaterniond(Eigen::Matrix3d(m.topLeftCorner<3, 3>())),
               m.topRightCorner<3, 1>());
  }
  return result;
}

void SetWorldToBoard(Rig* rig, const Rigid3& world_from_board) {
  for (size_t i = 0; i < rig->size(); ++i) {
    RigCamera& camera = (*rig)[i];
    camera.cam_from_world = camera.cam_from_world * world_from_board;
  }
}

void ScaleRig(Rig* rig, double scale) {
  for (size_t i = 0; i < rig->size(); ++i) (*rig)[i].cam_from_world.translation *= scale;
}

}  // namespace handlabel
