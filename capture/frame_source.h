#pragma once
// What a capture holds about one multi-view frame and the interface every capture reader
// (native layout, DexYCB, HO3D, OakInk) implements. The labeling job (pipeline/) reads
// frames only through FrameSource.
//
// Every point is in the rig's world frame (metres); 2D keypoints are distorted pixels
// in the full image. Keypoints are in the 21-point SNAP order (core/hand_model.h).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/hand_lbs.h"
#include "core/rig.h"

namespace handlabel {

// One view's 2D keypoints.
struct Keypoints2dView {
  Eigen::Matrix<double, kNumHandKeypoints, 2, Eigen::RowMajor> uv_px =
      Eigen::Matrix<double, kNumHandKeypoints, 2, Eigen::RowMajor>::Zero();
  // Per keypoint, in [0, 1]; 0 = not detected.
  Eigen::Matrix<double, kNumHandKeypoints, 1> confidence =
      Eigen::Matrix<double, kNumHandKeypoints, 1>::Zero();
};

struct FrameGroundTruth {
  Points3d keypoints;                // 21 x 3
  Points3d vertices;                 // V x 3, or empty when the capture has none
  std::optional<HandParams> params;  // when the capture has them
};

// Everything the capture holds about one multi-view frame. Images and masks stay on
// disk: the stages that need them read them.
struct FrameInput {
  std::string id;
  Rig rig;
  std::vector<std::string> image_paths;  // one per rig camera
  std::vector<std::string> mask_paths;   // one per rig camera, or empty
  // 2D keypoints from files, one entry per rig camera (nullopt: none for that view);
  // empty when the capture has no keypoint files.
  std::vector<std::optional<Keypoints2dView>> keypoints_2d;
  std::optional<FrameGroundTruth> ground_truth;
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
  // Which hand the capture shows, when it says (the hand model is built for it);
  // nullopt: the right hand.
  virtual std::optional<HandSide> Side() const { return std::nullopt; }
};

}  // namespace handlabel
