#pragma once
// Pictures of what the hand detector found in a view (network/detector/hand_detector.h):
// every palm box of the palm detector (yellow), the ROI the landmark model ran on (cyan,
// rotated), the 21 keypoints with the skeleton (finger colours; a keypoint's disc
// shrinks with its confidence, and a keypoint of confidence 0 is not drawn), and a
// caption: the source and presence of the detection, or in red the reason the view
// has none. `handlabel detect --overlays DIR` writes them per view, and a label job
// with `evidence.keypoints_2d: detector` adds them to its overlays.

#include <string>
#include <vector>

#include "image/draw.h"
#include "image/image.h"
#include "network/detector/hand_detector.h"

namespace handlabel {

inline constexpr Rgb kPalmBoxColor = {255, 220, 0};
inline constexpr Rgb kRoiColor = {0, 220, 255};
inline constexpr Rgb kNoHandColor = {255, 40, 40};
inline constexpr Rgb kCaptionColor = {255, 255, 255};

// The caption of a view: "PALM P0.93" (source and presence) or "NONE: LOW_PRESENCE".
std::string DetectionCaption(const ViewHandResult& view);

// Draws the view's detection onto `rgb` (the view's image, RGB).
void DrawHandDetection(const ViewHandResult& view, ImageU8* rgb);

// The corners of a ROI in handlabel pixels (pixel centres at integers), in order.
std::vector<Eigen::Vector2d> RoiCornersPx(const NormalizedRect& roi, int width,
                                          int height);

}  // namespace handlabel
