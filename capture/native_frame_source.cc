#include "capture/native_frame_source.h"

#include <algorithm>
#include <filesystem>

#include "cameras/rig_io.h"
#include "core/errors.h"

namespace handlabel {

Rig ReadCamerasFile(const std::string& path, const std::string& job_file) {
  if (!std::filesystem::exists(path)) {
    throw InputError(job_file, "cameras.file", "an existing rig file or COLMAP folder",
                     "'" + path + "'");
  }
  return ReadRig({std::filesystem::is_directory(path) ? "colmap" : "json", path});
}

NativeFrameSource::NativeFrameSource(const std::string& capture_dir,
                                     const std::optional<Rig>& cameras,
                                     const std::string& keypoint_files,
                                     const std::string& mask_files)
    : reader_(capture_dir), rig_(reader_.rig()) {
  if (cameras) {
    Rig reordered;
    for (const RigCamera& camera : reader_.rig().cameras()) {
      reordered.Add(cameras->Find(camera.name));  // InputError lists the known names
    }
    rig_ = reordered;
  }
  if (reader_.Has(kFileDetections)) {
    keypoint_kind_ = kFileDetections;
  } else if (reader_.Has(kFileKeypoints)) {
    keypoint_kind_ = kFileKeypoints;
  }
  if (reader_.Has(kFileDetectionMask)) {
    mask_kind_ = kFileDetectionMask;
  } else if (reader_.Has(kFileMask)) {
    mask_kind_ = kFileMask;
  }
  if (keypoint_files == "none") {
    keypoint_kind_.clear();
  } else if (keypoint_files != "auto") {
    keypoint_kind_ = keypoint_files == "detections" ? kFileDetections : kFileKeypoints;
  }
  if (mask_files != "auto")
    mask_kind_ = mask_files == "detections" ? kFileDetectionMask : kFileMask;
  for (const std::string& kind : {keypoint_kind_, mask_kind_}) {
    if (!kind.empty() && !reader_.Has(kind))
      throw InputError(capture_dir, kind, "a capture with these files");
  }
}

std::vector<std::string> NativeFrameSource::FrameIds() const {
  std::vector<std::string> ids = reader_.manifest().frames;
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::string NativeFrameSource::Describe() const {
  return "native capture " + reader_.dir() + " (" + std::to_string(rig_.size()) +
         " cameras, " + std::to_string(reader_.num_frames()) +
         " frames, 2D keypoints: " + (keypoint_kind_.empty() ? "none" : keypoint_kind_) +
         ", masks: " + (mask_kind_.empty() ? "none" : mask_kind_) +
         ", ground truth: " + (reader_.Has(kFileGroundTruth) ? "yes" : "no") + ")";
}

std::string NativeFrameSource::KeypointsSource() const {
  return keypoint_kind_.empty() ? ""
                                : keypoint_kind_ + "/{frame}.json of " + reader_.dir();
}

std::optional<HandSide> NativeFrameSource::side() const {
  return ParseHandSide(reader_.manifest().hand_side,
                       reader_.dir() + "/" + kCaptureManifestFile, "hand_side");
}

FrameInput NativeFrameSource::Load(const std::string& id) const {
  const int f = reader_.FrameIndex(id);
  if (f < 0)
    throw InputError(reader_.dir() + "/capture.json", "frames", "frame '" + id + "'");
  FrameInput frame;
  frame.id = id;
  frame.rig = rig_;
  for (int c = 0; c < reader_.num_cameras(); ++c) {
    frame.image_paths.push_back(reader_.Path(kFileImage, f, c));
    if (!mask_kind_.empty()) frame.mask_paths.push_back(reader_.Path(mask_kind_, f, c));
    if (reader_.Has(kFileObjectMask))
      frame.object_mask_paths.push_back(reader_.Path(kFileObjectMask, f, c));
  }
  if (!keypoint_kind_.empty()) {
    DetectionsHandChoice hand;  // several hands: the capture's side
    const std::vector<ViewKeypoints> views =
        keypoint_kind_ == kFileDetections ? reader_.ReadDetections(f, side(), &hand)
                                          : reader_.ReadKeypoints(f);
    frame.evidence_hand = hand.Describe();
    for (const ViewKeypoints& view : views) {
      // Known: a finite position that the ground truth does not mark out of frame.
      Keypoints2d out;
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        const bool known = view.keypoints.uv_px.row(k).allFinite() &&
                           (keypoint_kind_ == kFileDetections || view.visibility[k] > 0);
        if (!known) continue;
        out.uv_px.row(k) = view.keypoints.uv_px.row(k);
        out.confidence(k) = view.keypoints.confidence(k);
      }
      frame.keypoints_2d.push_back(out);
    }
  }
  if (reader_.Has(kFileGroundTruth)) {
    const HandGroundTruth gt = reader_.ReadGroundTruth(f);
    FrameGroundTruth truth;
    truth.keypoints = gt.keypoints;
    truth.vertices = gt.vertices;
    truth.params = gt.params;
    frame.ground_truth = truth;
  }
  return frame;
}

}  // namespace handlabel
