#pragma once
// A contact sheet of one capture frame: every view in a grid, each with the hand mask's
// outline drawn over the image and the ground-truth 2D keypoints and skeleton drawn
// (visible keypoints filled, occluded ones hollow, out-of-frame ones left out), so a
// person can check a capture at a glance.

#include "capture/capture_reader.h"
#include "image/image.h"

namespace handlabel {

struct ContactSheetOptions {
  int columns = 4;           // views per row (>= 1)
  int tile_width = 320;      // each view is scaled to this width (>= 16)
  bool mask_overlay = true;  // outline the hand mask
  // Show a square crop around the hand (its in-frame keypoints' box, enlarged 1.6x)
  // instead of the whole view; views without keypoints in frame show the whole image.
  bool crop_to_hand = false;
  bool keypoints = true;    // draw keypoints and skeleton
  bool detections = false;  // also draw simulated detections (crosses), if present
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

ImageU8 MakeContactSheet(const CaptureReader& capture, int frame,
                         const ContactSheetOptions& options = {});

}  // namespace handlabel
