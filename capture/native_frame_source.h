#pragma once
// The labeling job's frame source for a capture in the native layout
// (capture_reader.h, docs/capture-format.md). Which files serve as what:
//   2D keypoints (evidence.keypoints_2d: files)  detections/{frame}.json when the
//       capture has them (what a 2D detector produced), else keypoints/{frame}.json
//   masks (evidence.masks: files)                detections/masks/... when present,
//       else masks/...
//   ground truth                                 ground_truth/{frame}.json if present
// Cameras come from the capture's rig, or from cameras.file (matched by camera name).

#include <memory>
#include <optional>
#include <string>

#include "capture/capture_reader.h"
#include "capture/frame_source.h"
#include "geometry/rig.h"

namespace handlabel {

class NativeFrameSource : public FrameSource {
 public:
  // Throws InputError naming the capture's files, or `cameras_file` when its cameras
  // do not cover the capture's. keypoint_files ("detections" | "keypoints") and
  // mask_files ("detections" | "truth") override the choice above ("auto" keeps it);
  // keypoint_files "none" reads no keypoint file (a job whose 2D comes from elsewhere
  // must not fail a frame on a file it does not use).
  explicit NativeFrameSource(const std::string& capture_dir,
                             const std::optional<Rig>& cameras = std::nullopt,
                             const std::string& keypoint_files = "auto",
                             const std::string& mask_files = "auto");
  std::vector<std::string> FrameIds() const override;
  FrameInput Load(const std::string& id) const override;
  std::string Describe() const override;
  std::string KeypointsSource() const override;
  std::optional<HandSide> side() const override;
  const CaptureReader& reader() const { return reader_; }

 private:
  CaptureReader reader_;
  Rig rig_;                    // capture camera order
  std::string keypoint_kind_;  // "" = none
  std::string mask_kind_;      // "" = none
};

// A rig file for cameras.file: a folder is a COLMAP model, anything else the project's
// JSON rig file (cameras/rig_io.h).
Rig ReadCamerasFile(const std::string& path, const std::string& job_file);

}  // namespace handlabel
