#pragma once
// A synthetic board capture on a DexYCB-like rig, for tests, benchmarks and demos:
// cameras on a ring around a table looking at its centre, a board lying on the table at
// random positions, yaws and tilts, corners projected exactly through the true
// (distorted) cameras plus Gaussian pixel noise. World = table frame (z up, metres).

#include <cstdint>
#include <map>
#include <string>

#include "calib/board_calib.h"
#include "calib/board_render.h"

namespace handlabel {

struct SyntheticBoardCaptureOptions {
  int num_cameras = 8;
  int width = 640;
  int height = 480;
  int num_frames = 30;  // board poses on the table, seen by several cameras
  // Extra board poses held in front of each camera (0.25-0.45 m away, tilted up to
  // 45 degrees), as people do to pin down each camera's intrinsics.
  int near_frames_per_camera = 8;
  double near_tilt_deg = 45;        // per axis, for the near frames
  double near_distance_min = 0.25;  // metres
  double near_distance_max = 0.45;
  double corner_noise_px = 0.3;   // Gaussian sigma per coordinate
  double ring_radius_min = 0.55;  // camera distance from the table centre, metres
  double ring_radius_max = 0.80;
  double height_min = 0.40;  // camera height above the table, metres
  double height_max = 0.70;
  double max_board_tilt_deg = 40;  // board tilt away from lying flat
  double max_view_angle_deg = 70;  // cameras seeing the board more obliquely skip it
  int min_corners = 6;             // fewer visible corners: the camera skips the frame
  uint64_t seed = 1;
  void Check(const std::string& source) const;
};

struct SyntheticBoardCapture {
  Rig rig;  // ground truth; distortion model OPENCV
  // Per frame key: "000000", ... for table frames, "near<cam>_<i>" for near frames.
  std::map<std::string, Rigid3> world_from_board;
  std::vector<CameraBoardViews> views;  // noisy corner observations
};

SyntheticBoardCapture SynthesizeBoardCapture(const BoardSpec& board,
                                             const SyntheticBoardCaptureOptions& options);

// Renders every frame of every camera to `dir`/<camera>/<frame>.png (all frames, also
// those where the board is out of view: the detector must cope). Returns the number of
// images written.
int RenderBoardCapture(const SyntheticBoardCapture& capture, const BoardSpec& board,
                       const std::string& dir, const BoardRenderOptions& options = {},
                       uint64_t seed = 1);

}  // namespace handlabel
