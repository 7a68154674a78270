#pragma once
// A label series as COCO-WholeBody-style 2D hand annotations, one image per frame and
// view (docs/exports.md): the label's 21 keypoints and mesh projected with the
// capture's cameras (distortion included, as the overlays draw them).
//   images       id, file_name (the view's image file as the capture names it), width,
//                height, and frame, camera
//   annotations  one per image the hand is in: <side>hand_kpts 21 x (x, y, v) in SNAP
//                order (COCO-WholeBody's hand order), v = 2 for a keypoint in front of
//                the camera and inside the image, else 0 with x = y = 0 (occlusion is
//                not judged); <side>hand_box [x, y, w, h] = the projected mesh's extent
//                clipped to the image; <side>hand_valid true; the other hand, the body,
//                feet and face empty and invalid; bbox = the hand box, category 1
//   categories   person, with COCO-WholeBody's hand keypoint names
// Pixels: the centre of the top-left pixel is (0, 0) (OpenCV; COCO keypoint indices).

#include <nlohmann/json.hpp>
#include <string>

#include "capture/frame_source.h"
#include "exports/label_series.h"

namespace handlabel {

// `source`: the capture the labels were made from (its cameras and image files, frame
// by frame). Throws InputError naming the frame when the capture does not have it.
nlohmann::json CocoWholeBodyHands(const LabelSeries& series, const FrameSource& source);

}  // namespace handlabel
