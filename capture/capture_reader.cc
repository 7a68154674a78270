#include "capture/capture_reader.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "cameras/rig_json.h"
#include "core/errors.h"
#include "core/json_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

// Strict: repeated keys are refused too (json_util.h).
nlohmann::json ReadJsonFile(const std::string& path) {
  if (!fs::exists(path)) {
    throw InputError(path, "file", "an existing readable JSON file", "missing");
  }
  return ReadJsonFileStrict(path);
}

// Detections with no keypoint that has a position and a confidence above 0 in any view
// give the fitter nothing: the frame must fail by name, not be labelled from nothing.
void RequireSomeEvidence(const std::vector<ViewKeypoints>& views,
                         const std::string& path) {
  for (const ViewKeypoints& v : views) {
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (v.keypoints.confidence[k] > 0 && std::isfinite(v.keypoints.uv_px(k, 0)) &&
          std::isfinite(v.keypoints.uv_px(k, 1))) {
        return;
      }
    }
  }
  throw InputError(path, "confidence",
                   "at least one detected keypoint (confidence > 0, with a position) in "
                   "some view",
                   "none in " + std::to_string(views.size()) + " views");
}

}  // namespace

CaptureReader::CaptureReader(const std::string& dir) : dir_(dir) {
  const std::string manifest_path = (fs::path(dir) / kCaptureManifestFile).string();
  if (!fs::is_directory(dir)) {
    throw InputError(dir, "capture folder", "an existing folder", "missing");
  }
  if (!fs::exists(manifest_path)) {
    throw InputError(manifest_path, "file",
                     "a capture manifest (the folder is not a capture, or its writer did "
                     "not finish)",
                     "missing");
  }
  manifest_ = ManifestFromJson(ReadJsonFile(manifest_path), manifest_path);
  const std::string rig_path = (fs::path(dir) / manifest_.rig_file).string();
  const Rig file_rig = ReadRigJson(rig_path);
  for (const std::string& name : manifest_.cameras) {
    if (file_rig.IndexOf(name) < 0) {
      throw InputError(manifest_path, "cameras",
                       "camera names that " + manifest_.rig_file + " defines", name);
    }
    rig_.Add(file_rig.Find(name));  // present: checked above
  }
  if (rig_.empty())
    throw InputError(manifest_path, "cameras", "at least one camera", "none");
  if (manifest_.frames.empty())
    throw InputError(manifest_path, "frames", "at least one frame", "none");
}

const std::string& CaptureReader::frame_id(int frame) const {
  HL_CHECK(frame >= 0 && frame < num_frames(), "frame index out of range");
  return manifest_.frames[frame];
}

int CaptureReader::FrameIndex(const std::string& id) const {
  for (size_t i = 0; i < manifest_.frames.size(); ++i) {
    if (manifest_.frames[i] == id) return static_cast<int>(i);
  }
  return -1;
}

void CaptureReader::RequireKind(const std::string& kind) const {
  if (!Has(kind)) {
    throw InputError((fs::path(dir_) / kCaptureManifestFile).string(), "files." + kind,
                     "a path pattern (this capture has no " + kind + " files)",
                     "missing");
  }
}

std::string CaptureReader::Path(const std::string& kind, int frame, int camera) const {
  RequireKind(kind);
  HL_CHECK(camera >= 0 && camera < num_cameras(), "camera index out of range");
  return (fs::path(dir_) /
          ExpandPattern(manifest_.files.at(kind), rig_[camera].name, frame_id(frame)))
      .string();
}

ImageU8 CaptureReader::ReadImage(int frame, int camera) const {
  ImageU8 image = ReadPng(Path(kFileImage, frame, camera));
  const Camera& cam = rig_[camera].camera;
  if (image.width != cam.width() || image.height != cam.height()) {
    throw InputError(Path(kFileImage, frame, camera), "size",
                     std::to_string(cam.width()) + "x" + std::to_string(cam.height()) +
                         " (camera " + rig_[camera].name + ")",
                     std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  if (image.channels == 1 || image.channels == 4) {  // normalise to RGB
    ImageU8 rgb(image.width, image.height, 3);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int c = 0; c < 3; ++c)
          rgb.at(x, y, c) = image.at(x, y, image.channels == 1 ? 0 : c);
    return rgb;
  }
  return image;
}

ImageU8 CaptureReader::ReadGray(const std::string& kind, int frame, int camera) const {
  const std::string path = Path(kind, frame, camera);
  ImageU8 image = ReadPng(path);
  const Camera& cam = rig_[camera].camera;
  if (image.channels != 1 || image.width != cam.width() || image.height != cam.height()) {
    throw InputError(path, "image",
                     "a 1-channel " + std::to_string(cam.width()) + "x" +
                         std::to_string(cam.height()) + " PNG",
                     std::to_string(image.channels) + " channels " +
                         std::to_string(image.width) + "x" +
                         std::to_string(image.height));
  }
  return image;
}

ImageU8 CaptureReader::ReadMask(int frame, int camera) const {
  return ReadGray(kFileMask, frame, camera);
}
ImageU8 CaptureReader::ReadObjectMask(int frame, int camera) const {
  return ReadGray(kFileObjectMask, frame, camera);
}
ImageU8 CaptureReader::ReadDetectionMask(int frame, int camera) const {
  return ReadGray(kFileDetectionMask, frame, camera);
}

ImageF CaptureReader::ReadDepth(int frame, int camera) const {
  const ImageU16 raw = ReadPng16(Path(kFileDepth, frame, camera));
  ImageF depth(raw.width, raw.height, 1);
  for (size_t i = 0; i < raw.data.size(); ++i) {
    depth.data[i] = static_cast<float>(raw.data[i] * manifest_.depth_unit_m);
  }
  return depth;
}

std::vector<ViewKeypoints> CaptureReader::ViewsOfRecord(const nlohmann::json& record,
                                                        const std::string& path,
                                                        int frame) const {
  // Rig order, matched by camera name; every camera must be present once.
  const std::vector<std::optional<ViewKeypoints>> views =
      FrameKeypointsFromJson(record, path, frame_id(frame), rig_);
  std::vector<ViewKeypoints> ordered;
  for (size_t c = 0; c < rig_.size(); ++c) {
    if (!views[c])
      throw InputError(path, "views", "a view for camera " + rig_[c].name, "missing");
    ordered.push_back(*views[c]);
  }
  return ordered;
}

std::vector<ViewKeypoints> CaptureReader::ReadViews(const std::string& kind,
                                                    int frame) const {
  const std::string path = Path(kind, frame);
  return ViewsOfRecord(ReadJsonFile(path), path, frame);
}

std::vector<ViewKeypoints> CaptureReader::ReadKeypoints(int frame) const {
  return ReadViews(kFileKeypoints, frame);
}
std::vector<ViewKeypoints> CaptureReader::ReadDetections(
    int frame, std::optional<HandSide> side, DetectionsHandChoice* choice) const {
  const std::string path = Path(kFileDetections, frame);
  const DetectionsHandChoice chosen =
      ChooseDetectionsHand(ReadJsonFile(path), side, path);
  std::vector<ViewKeypoints> views = ViewsOfRecord(chosen.record, path, frame);
  RequireSomeEvidence(views, path);
  if (choice) *choice = chosen;
  return views;
}

HandGroundTruth CaptureReader::ReadGroundTruth(int frame) const {
  const std::string path = Path(kFileGroundTruth, frame);
  return GroundTruthFromJson(ReadJsonFile(path), path);
}

}  // namespace handlabel
