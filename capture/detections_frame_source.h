#pragma once
// 2D detections in the native format beside a capture read in place (a label job's
// evidence.detections; docs/labeling-jobs.md): for datasets that ship no 2D keypoints
// (HO3D, OakInk) they are the job's 2D. One file per frame, <folder>/<frame id>.json
// (ids with '/' are subfolders), in the shape of a native capture's
// detections/{frame}.json (docs/capture-format.md), which `handlabel detect` writes.
// Views are matched to the rig's cameras by name; a keypoint with confidence 0 or a
// null position is unknown; a camera without a view in the file has no 2D.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/capture_format.h"
#include "capture/replaced_2d_frame_source.h"

namespace handlabel {

class DetectionsFrameSource : public Replaced2dFrameSource {
 public:
  // Reads frames from `inner` and their 2D keypoints from `folder` (which must exist;
  // InputError naming `field` otherwise), replacing any the capture has.
  DetectionsFrameSource(std::unique_ptr<FrameSource> inner, const std::string& folder,
                        const std::string& field = "evidence.detections");
  // Throws InputError naming the detection file when it is missing or malformed.
  FrameInput Load(const std::string& id) const override;
  std::string KeypointsSource() const override;

 private:
  std::string folder_;
};

// The detections file of frame `frame` in rig order (nullopt: no view for that
// camera); its checks are FrameKeypointsFromJson's (capture_format.h). A file of several
// hands gives the hand of side `side` (ChooseDetectionsHand; nullopt: the first hand),
// which one into `choice` when given.
std::vector<std::optional<Keypoints2d>> ReadDetectionsFile(
    const std::string& path, const std::string& frame, const Rig& rig,
    std::optional<HandSide> side = std::nullopt, DetectionsHandChoice* choice = nullptr);

}  // namespace handlabel
