#pragma once
// Multi-camera calibration from board observations:
//  1. intrinsics and per-image board poses per camera (OpenCV calibrateCamera);
//  2. initial extrinsics by chaining relative poses over the camera-overlap graph:
//     a maximum spanning tree from the master camera, edges weighted by the corners
//     both cameras saw in the same frames; each edge takes the medoid of the
//     per-frame relative poses;
//  3. Ceres bundle adjustment of every camera's intrinsics and distortion, extrinsics
//     and every frame's board pose, with a Huber loss, and rounds of outlier rejection
//     (residuals above max(min_outlier_px, outlier_sigmas * robust sigma) are dropped);
//  4. the world frame is the master camera or the board in one frame.
// A "frame" is one moment at which several cameras saw the same board pose; frames are
// matched across cameras by key (the image file name).

#include <map>
#include <string>
#include <vector>

#include "calib/board_detect.h"
#include "calib/board_spec.h"
#include "geometry/rig.h"

namespace handlabel {

// Everything one camera saw.
struct CameraBoardViews {
  std::string name;
  int width = 0;
  int height = 0;
  std::map<std::string, BoardObservation> frames;  // frame key -> corners
};

struct BoardCalibOptions {
  // Camera model fitted for every camera (COLMAP numbering).
  CameraModelId model = CameraModelId::kOpenCV;
  // Master camera name; "" = the first camera.
  std::string master;
  // World frame: "camera" (the master camera), "board" (the board in the first frame,
  // by key, that the master camera saw) or "board:KEY" (the board in frame KEY).
  std::string world = "camera";
  // Huber loss scale in pixels.
  double huber_px = 1.0;
  // Outlier rejection rounds after the first solve (0 = none).
  int outlier_rounds = 3;
  // Residuals above max(min_outlier_px, outlier_sigmas * sigma) are outliers (5 sigma:
  // about 4e-6 of Gaussian residuals, so clean data needs no second solve); sigma is
  // estimated robustly from the median residual norm.
  double outlier_sigmas = 5.0;
  double min_outlier_px = 1.0;
  // A camera needs at least this many frames with detections.
  int min_frames_per_camera = 3;
  // Ceres iterations per solve.
  int max_iterations = 200;
  // Ceres threads (keep small on shared machines).
  int num_threads = 1;
  void Check(const std::string& source) const;
};

struct CameraCalibStats {
  std::string name;
  int frames = 0;             // frames with detections
  int observations = 0;       // corners kept (inliers)
  int outliers = 0;           // corners rejected
  double rms_px = 0;          // reprojection RMS over inliers
  double initial_rms_px = 0;  // of the per-camera OpenCV calibration
};

struct CornerResidual {
  int camera = 0;  // index into the rig
  std::string frame;
  int corner_id = 0;
  Eigen::Vector2d observed = Eigen::Vector2d::Zero();
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();  // projected - observed, px
  bool inlier = true;
};

struct BoardCalibResult {
  Rig rig;
  std::string world;  // description, e.g. "camera:cam0" or "board:000012"
  std::map<std::string, Rigid3> world_from_board;  // per frame key
  std::vector<CameraCalibStats> stats;             // rig order
  std::vector<CornerResidual> residuals;
  double rms_px = 0;  // over all inliers
  // Spanning-tree edges used for the initial extrinsics: (parent, child, weight).
  std::vector<std::tuple<std::string, std::string, int>> tree;
};

// Throws InputError for too few detections per camera, cameras that cannot be linked
// to the master camera (naming them), unknown master/world, or a failed solve.
BoardCalibResult CalibrateBoardRig(const std::vector<CameraBoardViews>& views,
                                   const BoardSpec& board,
                                   const BoardCalibOptions& options = {});

}  // namespace handlabel
