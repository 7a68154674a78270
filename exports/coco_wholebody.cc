#include "exports/coco_wholebody.h"

#include <optional>
#include <set>

#include "core/errors.h"
#include "hand/hand_skeleton.h"

namespace handlabel {
namespace {

using nlohmann::json;

struct Box {
  Eigen::Vector2d min = Eigen::Vector2d::Constant(1e300);
  Eigen::Vector2d max = Eigen::Vector2d::Constant(-1e300);
  void Add(const Eigen::Vector2d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};

// The projected mesh's extent clipped to the image; nullopt when none of it is there.
std::optional<Box> HandBox(const RigCamera& camera, const Points3d& vertices) {
  Box box;
  for (int v = 0; v < vertices.rows(); ++v) {
    Eigen::Vector2d uv;
    if (camera.ProjectWorld(vertices.row(v).transpose(), &uv)) box.Add(uv);
  }
  const Eigen::Vector2d size(camera.camera.width(), camera.camera.height());
  box.min = box.min.cwiseMax(Eigen::Vector2d::Zero());
  box.max = box.max.cwiseMin(size);
  if (!(box.max.x() > box.min.x() && box.max.y() > box.min.y())) return std::nullopt;
  return box;
}

// 21 x (x, y, v); returns how many are visible (v = 2).
int ProjectKeypoints(const RigCamera& camera, const Points3d& keypoints, json* out) {
  *out = json::array();
  int visible = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    Eigen::Vector2d uv;
    const bool seen = camera.ProjectWorld(keypoints.row(k).transpose(), &uv) &&
                      camera.camera.InImage(uv);
    visible += seen;
    out->push_back(seen ? uv.x() : 0.0);
    out->push_back(seen ? uv.y() : 0.0);
    out->push_back(seen ? 2 : 0);
  }
  return visible;
}

json EmptyAnnotation(const std::string& side) {
  const std::string other = side == "left" ? "right" : "left";
  const auto zeros = [](int n) { return json(std::vector<double>(3 * n, 0.0)); };
  return {{"category_id", 1},
          {"iscrowd", 0},
          {"segmentation", json::array()},
          {"num_keypoints", 0},
          {"keypoints", zeros(17)},
          {"foot_kpts", zeros(6)},
          {"face_kpts", zeros(68)},
          {other + "hand_kpts", zeros(kNumHandKeypoints)},
          {"face_box", {0, 0, 0, 0}},
          {other + "hand_box", {0, 0, 0, 0}},
          {"face_valid", false},
          {"foot_valid", false},
          {other + "hand_valid", false}};
}

json Categories() {
  json body = json::array();
  for (const char* name :
       {"nose", "left_eye", "right_eye", "left_ear", "right_ear", "left_shoulder",
        "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
        "left_hip", "right_hip", "left_knee", "right_knee", "left_ankle", "right_ankle"})
    body.push_back(name);
  json hand = json::array();
  for (const char* name : kSnapKeypointNames) hand.push_back(name);
  return json::array({{{"id", 1},
                       {"name", "person"},
                       {"supercategory", "person"},
                       {"keypoints", body},
                       {"hand_keypoints", hand}}});
}

}  // namespace

json CocoWholeBodyHands(const LabelSeries& series, const FrameSource& source) {
  const std::vector<std::string> ids = source.FrameIds();
  const std::set<std::string> known(ids.begin(), ids.end());
  const std::string side = HandSideName(series.side);
  json images = json::array(), annotations = json::array();
  for (const LabelRecord& label : series.labels) {
    if (!known.count(label.frame)) {
      throw InputError(source.Describe(), "frame '" + label.frame + "'",
                       "the frame the label was made from (is this the job's capture?)",
                       "no such frame");
    }
    const FrameInput frame = source.Load(label.frame);
    for (size_t v = 0; v < frame.rig.size(); ++v) {
      const RigCamera& camera = frame.rig[v];
      const int image_id = static_cast<int>(images.size()) + 1;
      images.push_back(
          {{"id", image_id},
           {"file_name", v < frame.image_paths.size() ? frame.image_paths[v] : ""},
           {"width", camera.camera.width()},
           {"height", camera.camera.height()},
           {"frame", label.frame},
           {"camera", camera.name}});
      json keypoints;
      const int visible = ProjectKeypoints(camera, label.mesh.keypoints, &keypoints);
      const std::optional<Box> box = HandBox(camera, label.mesh.vertices);
      if (visible == 0 || !box) continue;  // the hand is not in this view
      const Eigen::Vector2d size = box->max - box->min;
      const json xywh = {box->min.x(), box->min.y(), size.x(), size.y()};
      json a = EmptyAnnotation(side);
      a["id"] = static_cast<int>(annotations.size()) + 1;
      a["image_id"] = image_id;
      a["bbox"] = xywh;
      a["area"] = size.x() * size.y();
      a[side + "hand_kpts"] = keypoints;
      a[side + "hand_box"] = xywh;
      a[side + "hand_valid"] = true;
      annotations.push_back(std::move(a));
    }
  }
  return {{"info",
           {{"description", "handlabel labels as COCO-WholeBody-style hand keypoints"},
            {"labels", series.labels_dir},
            {"hand_side", side}}},
          {"images", images},
          {"annotations", annotations},
          {"categories", Categories()}};
}

}  // namespace handlabel
