#pragma once
// Metric scale for an SfM rig (COLMAP's arbitrary unit) from a calibration board seen by
// several of its cameras at the same moment: every board corner seen in two or more
// cameras of one frame is triangulated with the unscaled rig, and the scale is the
// median, over pairs of corners of the same frame, of (true distance on the board /
// triangulated distance). The median keeps wrong detections out.

#include <string>
#include <vector>

#include "calib/board_calib.h"
#include "calib/board_spec.h"
#include "geometry/rig.h"
#include "geometry/rigid3.h"

namespace handlabel {

struct BoardScaleResult {
  double scale = 1;   // metres per rig unit
  int frames = 0;     // frames with at least two triangulated corners
  int corners = 0;    // corners triangulated over all frames
  int pairs = 0;      // corner pairs the median is over
  double spread = 0;  // median absolute deviation of the ratios / scale
  // The board's pose (metres, in the rig's world scaled by `scale`) in the first frame
  // (by key) with 3 or more triangulated corners, and that frame's key.
  Rigid3 world_from_board;
  std::string board_frame;
};

// `views` are board detections per camera (matched to the rig by camera name; frames by
// key). Throws InputError naming `source` when no frame has two corners seen by two
// cameras of the rig (say which cameras had detections).
BoardScaleResult ScaleFromBoard(const Rig& rig,
                                const std::vector<CameraBoardViews>& views,
                                const BoardSpec& board, const std::string& source);

// Re-expresses the rig with the world at a board pose: cam_from_board =
// cam_from_world * world_from_board.
void SetWorldToBoard(Rig* rig, const Rigid3& world_from_board);

// Multiplies every camera's translation by `scale` (cameras keep their rotations, the
// world origin stays).
void ScaleRig(Rig* rig, double scale);

}  // namespace handlabel
