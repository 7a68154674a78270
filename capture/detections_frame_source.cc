#include "capture/detections_frame_source.h"

#include <cmath>
#include <filesystem>

#include "capture/capture_format.h"
#include "core/errors.h"
#include "core/json_util.h"

namespace handlabel {

namespace fs = std::filesystem;

std::vector<std::optional<Keypoints2d>> ReadDetectionsFile(const std::string& path,
                                                           const std::string& frame,
                                                           const Rig& rig,
                                                           std::optional<HandSide> side,
                                                           DetectionsHandChoice* choice) {
  if (!fs::exists(path)) {
    throw InputError(path, "(file)",
                     "the frame's 2D detections (native detections/{frame}.json format)",
                     "missing");
  }
  std::vector<std::optional<Keypoints2d>> out(rig.size());
  const DetectionsHandChoice chosen =
      ChooseDetectionsHand(ReadJsonFileStrict(path), side, path);
  if (choice) *choice = chosen;
  const std::vector<std::optional<ViewKeypoints>> views =
      FrameKeypointsFromJson(chosen.record, path, frame, rig);
  for (size_t c = 0; c < rig.size(); ++c) {
    if (!views[c]) continue;
    Keypoints2d keypoints;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      const double confidence = views[c]->keypoints.confidence(k);
      if (!views[c]->keypoints.uv_px.row(k).allFinite() || !(confidence > 0)) continue;
      keypoints.uv_px.row(k) = views[c]->keypoints.uv_px.row(k);
      keypoints.confidence(k) = confidence;
    }
    out[c] = keypoints;
  }
  return out;
}

DetectionsFrameSource::DetectionsFrameSource(std::unique_ptr<FrameSource> inner,
                                             const std::string& folder,
                                             const std::string& field)
    : Replaced2dFrameSource(std::move(inner)), folder_(folder) {
  if (!fs::is_directory(folder)) {
    throw InputError(folder, field,
                     "a folder of 2D detections, <frame id>.json per frame",
                     fs::exists(folder) ? "not a folder" : "not found");
  }
}

FrameInput DetectionsFrameSource::Load(const std::string& id) const {
  FrameInput frame = inner_->Load(id);
  DetectionsHandChoice hand;  // several hands: the capture's side
  frame.keypoints_2d =
      ReadDetectionsFile((fs::path(folder_) / (id + ".json")).string(), id, frame.rig,
                         side().value_or(HandSide::kRight), &hand);
  frame.evidence_hand = hand.Describe();
  return frame;
}

std::string DetectionsFrameSource::KeypointsSource() const {
  return "detections folder " + folder_ + " (<frame>.json)";
}

}  // namespace handlabel
