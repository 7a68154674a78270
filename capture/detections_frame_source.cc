#include "capture/detections_frame_source.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/capture_format.h"
#include "core/errors.h"

namespace handlabel {

namespace fs = std::filesystem;

std::vector<std::optional<Keypoints2d>> ReadDetectionsFile(const std::string& path,
                                                           const Rig& rig) {
  std::ifstream in(path);
  if (!in) {
    throw InputError(path, "(file)",
                     "the frame's 2D detections (native detections/{frame}.json format)",
                     "missing");
  }
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "content", "valid JSON", e.what());
  }
  std::vector<std::optional<Keypoints2d>> out(rig.size());
  for (const ViewKeypoints& view : ViewKeypointsFromJson(json, path)) {
    const int c = rig.IndexOf(view.camera);
    if (c < 0) {
      throw InputError(path, "views.camera", "a camera of the capture's rig",
                       "'" + view.camera + "'");
    }
    if (out[c]) throw InputError(path, "views.camera", "each camera once", view.camera);
    Keypoints2d keypoints;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      const double confidence = view.keypoints.confidence(k);
      if (!view.keypoints.uv_px.row(k).allFinite() || !(confidence > 0)) continue;
      keypoints.uv_px.row(k) = view.keypoints.uv_px.row(k);
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
  frame.keypoints_2d =
      ReadDetectionsFile((fs::path(folder_) / (id + ".json")).string(), frame.rig);
  return frame;
}

std::string DetectionsFrameSource::KeypointsSource() const {
  return "detections folder " + folder_ + " (<frame>.json)";
}

}  // namespace handlabel
