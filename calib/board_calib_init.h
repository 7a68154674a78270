#pragma once
// Initial values for board calibration: per-camera intrinsics and board poses from
// OpenCV's calibrateCamera, and extrinsics chained over the camera-overlap graph.

#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "calib/board_calib.h"

namespace handlabel {

struct InitialCamera {
  Camera camera;                                 // in the requested model
  std::map<std::string, Rigid3> cam_from_board;  // per frame key
  double rms_px = 0;
};

// Throws InputError naming the camera if OpenCV cannot calibrate it.
InitialCamera InitialIntrinsics(const CameraBoardViews& views, const BoardSpec& board,
                                CameraModelId model);

// cam_from_master for every camera by chaining medoid relative poses along a maximum
// spanning tree of shared corner counts. Throws InputError naming the cameras that
// share no frame with the master's component. `tree` receives (parent, child, weight).
std::vector<Rigid3> ChainExtrinsics(
    const std::vector<CameraBoardViews>& views, const std::vector<InitialCamera>& initial,
    size_t master, std::vector<std::tuple<std::string, std::string, int>>* tree);

// The element of `poses` with the smallest summed distance (angle in radians plus
// translation / scale) to all others: a robust "average" of relative poses.
Rigid3 MedoidPose(const std::vector<Rigid3>& poses, double scale);

}  // namespace handlabel
