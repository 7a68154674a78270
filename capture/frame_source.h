#pragma once
// What a capture holds about one multi-view frame and the interface every capture reader
// (native layout, DexYCB, HO3D, OakInk) implements. The labeling job (pipeline/) reads
// frames only through FrameSource.
//
// Every point is in the rig's world frame (metres); 2D keypoints are distorted pixels
// in the full image. Keypoints are in the 21-point SNAP order (hand/hand_model.h).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/stage_times.h"
#include "geometry/rig.h"
#include "hand/hand_lbs.h"
#include "hand/keypoints2d.h"
#include "image/image.h"
#include "image/mask_image.h"

namespace handlabel {

struct FrameGroundTruth {
  Points3d keypoints;                // 21 x 3
  Points3d vertices;                 // V x 3, or empty when the capture has none
  std::optional<HandParams> params;  // when the capture has them
};

// Everything the capture holds about one multi-view frame. Images and masks stay on
// disk: the stages that need them read them, unless `images` holds them already.
struct FrameInput {
  std::string id;
  Rig rig;
  std::vector<std::string> image_paths;  // one per rig camera
  // The views' images decoded once for several stages (the network's crops, the
  // detector, the overlays): RGB, one per rig camera, each checked against its camera's
  // size; a 0 x 0 image for a view without an image file. Empty: read image_paths
  // (capture/frame_images.h).
  std::vector<ImageU8> images;
  std::vector<std::string> mask_paths;  // one per rig camera, or empty
  // Object label maps (0 = none, k = object k), one per rig camera, or empty when the
  // capture has none: pixels where an object may hide the hand.
  std::vector<std::string> object_mask_paths;
  // Masks a reader decoded itself (a dataset's segmentation inside its label files),
  // one per rig camera (an empty image: none for that view), or empty. When set they
  // take the place of mask_paths / object_mask_paths: 255 = hand (masks) or object
  // (object_masks).
  std::vector<MaskImage> masks;
  std::vector<MaskImage> object_masks;
  // 2D keypoints from files, one entry per rig camera (nullopt: none for that view);
  // empty when the capture has no keypoint files. Unknown keypoints: confidence 0 and
  // position 0.
  std::vector<std::optional<Keypoints2d>> keypoints_2d;
  // Which hand keypoints_2d are when the frame's detections hold several
  // (`detect --max-hands`, docs/detector.md): "hand 2 of 2 (left)", the hand of the
  // capture's side; "" with one hand. The label job puts it in the frame log.
  std::string evidence_hand;
  std::optional<FrameGroundTruth> ground_truth;
  // Where the hand is expected in views without 2D keypoints to cut the network's crop
  // around: 3D points (world frame) whose projection the crop frames, e.g. the previous
  // frame's label keypoints in a job that tracks (evidence.detector_every). Empty: none.
  Points3d crop_prior;
  // Wall seconds the stages that loaded or processed the frame spent on it beyond
  // reading it, per stage (core/stage_times.h), e.g. a reader that detects the hand:
  // "detect.palm", "detect.landmarks", "detect.other". The label job adds its own
  // stages and records them in the frame log (pipeline/frame_log.h).
  StageSeconds stage_seconds;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Every frame id of the capture, sorted; ids are file-name safe (see label_record.h).
  virtual std::vector<std::string> FrameIds() const = 0;
  // Thread-safe. Throws (InputError for bad files) when the frame cannot be read; the
  // runner records the message as the frame's failure reason.
  virtual FrameInput Load(const std::string& id) const = 0;
  // One line for logs ("native capture /data/cap1, 8 cameras, 1200 frames").
  virtual std::string Describe() const = 0;
  // Where the frames' 2D keypoints (FrameInput::keypoints_2d) come from, for logs and
  // the job summary ("labels_*.npz joint_2d", "detections folder /d"); "" when the
  // capture has none (the default).
  virtual std::string KeypointsSource() const { return ""; }
  // Which hand the capture shows, when it says (the hand model is built for it);
  // nullopt: the right hand.
  virtual std::optional<HandSide> side() const { return std::nullopt; }
};

}  // namespace handlabel
