#pragma once
// Reads a capture in the native layout (capture_format.h, docs/capture-format.md): the
// manifest, the rig, and per frame and view the images, masks, depth, 2D keypoints,
// detections and ground truth. Used by the label pipeline, fitting and training.
// Every error names the file and the field.

#include <optional>
#include <string>
#include <vector>

#include "capture/capture_format.h"
#include "geometry/rig.h"
#include "image/image.h"

namespace handlabel {

class CaptureReader {
 public:
  // Reads `dir`/capture.json and the rig it names. Throws InputError if the folder is
  // not a capture, the version is unknown, or the manifest's cameras do not match the
  // rig's.
  explicit CaptureReader(const std::string& dir);

  const std::string& dir() const { return dir_; }
  const CaptureManifest& manifest() const { return manifest_; }
  const Rig& rig() const { return rig_; }  // manifest camera order
  int num_frames() const { return static_cast<int>(manifest_.frames.size()); }
  int num_cameras() const { return static_cast<int>(rig_.size()); }
  const std::string& frame_id(int frame) const;
  // Frame index of an id; -1 if absent.
  int FrameIndex(const std::string& id) const;

  // Whether the capture has files of a kind (kFileMask, kFileDepth, ...).
  bool Has(const std::string& kind) const { return manifest_.files.count(kind) > 0; }
  // Absolute path of a per-view file (kind with {camera}) or per-frame file.
  std::string Path(const std::string& kind, int frame, int camera = 0) const;

  ImageU8 ReadImage(int frame, int camera) const;       // RGB (3 channels)
  ImageU8 ReadMask(int frame, int camera) const;        // hand mask, 0/255
  ImageU8 ReadObjectMask(int frame, int camera) const;  // 0 = none, k = object k
  ImageF ReadDepth(int frame, int camera) const;        // metres, 0 = none
  ImageU8 ReadDetectionMask(int frame, int camera) const;
  // Per view, rig order (views are matched to cameras by name).
  std::vector<ViewKeypoints> ReadKeypoints(int frame) const;
  // A file of several hands (`detect --max-hands`): the hand of side `side`
  // (ChooseDetectionsHand, capture_format.h; nullopt: the first hand, as contact sheets
  // draw it), which one into `choice` when given.
  std::vector<ViewKeypoints> ReadDetections(int frame,
                                            std::optional<HandSide> side = std::nullopt,
                                            DetectionsHandChoice* choice = nullptr) const;
  HandGroundTruth ReadGroundTruth(int frame) const;

 private:
  void RequireKind(const std::string& kind) const;
  std::vector<ViewKeypoints> ReadViews(const std::string& kind, int frame) const;
  // The views of file `path` (frame `frame`) in rig order, every camera once.
  std::vector<ViewKeypoints> ViewsOfRecord(const nlohmann::json& record,
                                           const std::string& path, int frame) const;
  ImageU8 ReadGray(const std::string& kind, int frame, int camera) const;

  std::string dir_;
  CaptureManifest manifest_;
  Rig rig_;
};

}  // namespace handlabel
