#include "capture/capture_format.h"

#include <cmath>

#include "core/errors.h"

namespace handlabel {
namespace {

using nlohmann::json;

const json& Member(const json& j, const char* key, const std::string& source,
                   const std::string& where = "") {
  if (!j.is_object())
    throw InputError(source, where, "an object", j.dump().substr(0, 80));
  const auto it = j.find(key);
  if (it == j.end()) throw InputError(source, where + key, "a value", "missing");
  return *it;
}

std::string String(const json& j, const char* key, const std::string& source,
                   const std::string& where = "") {
  const json& v = Member(j, key, source, where);
  if (!v.is_string()) throw InputError(source, where + key, "a string", v.dump());
  return v.get<std::string>();
}

std::vector<std::string> StringList(const json& j, const char* key,
                                    const std::string& source) {
  const json& v = Member(j, key, source);
  if (!v.is_array()) throw InputError(source, key, "an array of strings", v.dump());
  std::vector<std::string> out;
  for (const json& s : v) {
    if (!s.is_string() || s.get<std::string>().empty()) {
      throw InputError(source, key, "non-empty strings", s.dump());
    }
    out.push_back(s.get<std::string>());
  }
  return out;
}

double Number(const json& v, const std::string& source, const std::string& field) {
  if (!v.is_number()) throw InputError(source, field, "a number", v.dump());
  return v.get<double>();
}

// A number, or null for NaN.
json NumberOrNull(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }
double NumberOrNan(const json& v, const std::string& source, const std::string& field) {
  return v.is_null() ? std::nan("") : Number(v, source, field);
}

json Points(const Points3d& p) {
  json out = json::array();
  for (Eigen::Index i = 0; i < p.rows(); ++i) out.push_back({p(i, 0), p(i, 1), p(i, 2)});
  return out;
}

Points3d PointsFrom(const json& j, const std::string& source, const std::string& field,
                    Eigen::Index expected_rows) {
  if (!j.is_array() ||
      (expected_rows >= 0 && static_cast<Eigen::Index>(j.size()) != expected_rows)) {
    throw InputError(source, field,
                     expected_rows >= 0
                         ? std::to_string(expected_rows) + " points [x, y, z]"
                         : "an array of [x, y, z]",
                     j.is_array() ? std::to_string(j.size()) + " entries" : j.dump());
  }
  Points3d p(j.size(), 3);
  for (size_t i = 0; i < j.size(); ++i) {
    if (!j[i].is_array() || j[i].size() != 3) {
      throw InputError(source, field + "[" + std::to_string(i) + "]", "[x, y, z]",
                       j[i].dump());
    }
    for (int c = 0; c < 3; ++c) p(i, c) = Number(j[i][c], source, field);
  }
  return p;
}

Eigen::VectorXd VectorFrom(const json& j, const std::string& source,
                           const std::string& field, int expected) {
  if (!j.is_array() || (expected >= 0 && static_cast<int>(j.size()) != expected)) {
    throw InputError(source, field,
                     expected >= 0 ? std::to_string(expected) + " numbers" : "numbers",
                     j.dump().substr(0, 80));
  }
  Eigen::VectorXd v(j.size());
  for (size_t i = 0; i < j.size(); ++i) v[i] = Number(j[i], source, field);
  return v;
}

template <typename V>
json Array(const V& v) {
  json out = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v[i]);
  return out;
}

}  // namespace

json ManifestToJson(const CaptureManifest& m) {
  json j;
  j["format"] = "handlabel-capture";
  j["version"] = m.version;
  j["rig"] = m.rig_file;
  if (!m.colmap_dir.empty()) j["colmap"] = m.colmap_dir;
  j["cameras"] = m.cameras;
  j["frames"] = m.frames;
  j["files"] = m.files;
  j["depth_unit_m"] = m.depth_unit_m;
  j["world"] = m.world;
  j["hand_side"] = m.hand_side;
  j["generator"] = m.generator;
  return j;
}

CaptureManifest ManifestFromJson(const json& j, const std::string& source) {
  CaptureManifest m;
  if (String(j, "format", source) != "handlabel-capture") {
    throw InputError(source, "format", "\"handlabel-capture\"",
                     Member(j, "format", source).dump());
  }
  const json& version = Member(j, "version", source);
  if (!version.is_number_integer() || version.get<int>() != kCaptureFormatVersion) {
    throw InputError(
        source, "version",
        std::to_string(kCaptureFormatVersion) + " (this build reads only it)",
        version.dump());
  }
  m.rig_file = String(j, "rig", source);
  if (j.contains("colmap")) m.colmap_dir = String(j, "colmap", source);
  m.cameras = StringList(j, "cameras", source);
  m.frames = StringList(j, "frames", source);
  const json& files = Member(j, "files", source);
  if (!files.is_object())
    throw InputError(source, "files", "an object of patterns", files.dump());
  for (const auto& [kind, pattern] : files.items()) {
    if (!pattern.is_string()) {
      throw InputError(source, "files." + kind, "a path pattern string", pattern.dump());
    }
    m.files[kind] = pattern.get<std::string>();
  }
  if (j.contains("depth_unit_m")) {
    m.depth_unit_m = Number(j["depth_unit_m"], source, "depth_unit_m");
    if (!(m.depth_unit_m > 0)) throw InputError(source, "depth_unit_m", "> 0");
  }
  if (j.contains("world")) m.world = String(j, "world", source);
  if (j.contains("hand_side")) {
    m.hand_side = String(j, "hand_side", source);
    if (m.hand_side != "right" && m.hand_side != "left") {
      throw InputError(source, "hand_side", "\"right\" or \"left\"", m.hand_side);
    }
  }
  if (j.contains("generator")) m.generator = j["generator"];
  return m;
}

std::string ExpandPattern(const std::string& pattern, const std::string& camera,
                          const std::string& frame) {
  std::string out = pattern;
  for (const auto& [key, value] :
       {std::pair<std::string, std::string>{"{camera}", camera}, {"{frame}", frame}}) {
    for (size_t at = out.find(key); at != std::string::npos; at = out.find(key, at)) {
      out.replace(at, key.size(), value);
      at += value.size();
    }
  }
  return out;
}

std::string FrameId(int index) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06d", index);
  return buf;
}

json ViewKeypointsToJson(const std::string& frame,
                         const std::vector<ViewKeypoints>& views, bool ground_truth) {
  json out;
  out["frame"] = frame;
  out["views"] = json::array();
  for (const ViewKeypoints& v : views) {
    json jv;
    jv["camera"] = v.camera;
    json kp = json::array();
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      kp.push_back(
          {NumberOrNull(v.keypoints.uv_px(k, 0)), NumberOrNull(v.keypoints.uv_px(k, 1))});
    }
    jv["keypoints"] = kp;
    if (ground_truth) {
      jv["visibility"] = v.visibility;
      jv["status"] = v.status;
      jv["hand_pixels"] = v.hand_pixels;
    } else {
      const KeypointConfidences& c = v.keypoints.confidence;
      jv["confidence"] = std::vector<double>(c.data(), c.data() + c.size());
    }
    out["views"].push_back(jv);
  }
  return out;
}

std::vector<ViewKeypoints> ViewKeypointsFromJson(const json& j,
                                                 const std::string& source) {
  const json& views = Member(j, "views", source);
  if (!views.is_array()) throw InputError(source, "views", "an array", views.dump());
  std::vector<ViewKeypoints> out;
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string where = "views[" + std::to_string(i) + "].";
    const json& jv = views[i];
    ViewKeypoints v;
    v.camera = String(jv, "camera", source, where);
    const json& kp = Member(jv, "keypoints", source, where);
    if (!kp.is_array() || kp.size() != kNumHandKeypoints) {
      throw InputError(source, where + "keypoints", "21 [x, y] pairs",
                       kp.dump().substr(0, 80));
    }
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!kp[k].is_array() || kp[k].size() != 2) {
        throw InputError(source, where + "keypoints", "[x, y] or [null, null]",
                         kp[k].dump());
      }
      v.keypoints.uv_px(k, 0) = NumberOrNan(kp[k][0], source, where + "keypoints");
      v.keypoints.uv_px(k, 1) = NumberOrNan(kp[k][1], source, where + "keypoints");
    }
    v.visibility.fill(-1);
    v.keypoints.confidence.setOnes();
    if (jv.contains("visibility")) {
      const Eigen::VectorXd vis =
          VectorFrom(jv["visibility"], source, where + "visibility", 21);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        v.visibility[k] = static_cast<int>(vis[k]);
        if (vis[k] != 0 && vis[k] != 1 && vis[k] != 2) {
          throw InputError(source, where + "visibility", "0, 1 or 2",
                           std::to_string(vis[k]));
        }
      }
    }
    if (jv.contains("confidence")) {
      const Eigen::VectorXd c =
          VectorFrom(jv["confidence"], source, where + "confidence", 21);
      v.keypoints.confidence = c;
    }
    if (jv.contains("status")) v.status = String(jv, "status", source, where);
    if (jv.contains("hand_pixels")) {
      v.hand_pixels =
          static_cast<int>(Number(jv["hand_pixels"], source, where + "hand_pixels"));
    }
    out.push_back(v);
  }
  return out;
}

json GroundTruthToJson(const std::string& frame, const HandGroundTruth& gt) {
  json j;
  j["frame"] = frame;
  j["hand_model"] = gt.hand_model;
  j["side"] = gt.side;
  j["pose_kind"] = gt.pose_kind;
  j["global_orient"] = Array(gt.params.global_orient);
  j["hand_pose"] = Array(gt.params.hand_pose);
  j["betas"] = Array(gt.params.betas);
  j["transl"] = Array(gt.params.transl);
  j["keypoints3d"] = Points(gt.keypoints);
  j["joints3d"] = Points(gt.joints);
  j["vertices"] = Points(gt.vertices);
  j["objects"] = json::array();
  for (const ObjectGroundTruth& o : gt.objects) {
    const Eigen::Quaterniond& q = o.world_from_object.rotation;
    j["objects"].push_back({{"kind", o.kind},
                            {"size", Array(o.size)},
                            {"world_from_object",
                             {{"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
                              {"translation", Array(o.world_from_object.translation)}}}});
  }
  return j;
}

HandGroundTruth GroundTruthFromJson(const json& j, const std::string& source) {
  HandGroundTruth gt;
  gt.hand_model = String(j, "hand_model", source);
  gt.side = String(j, "side", source);
  gt.pose_kind = String(j, "pose_kind", source);
  gt.params.global_orient =
      VectorFrom(Member(j, "global_orient", source), source, "global_orient", 3);
  gt.params.hand_pose =
      VectorFrom(Member(j, "hand_pose", source), source, "hand_pose", 45);
  gt.params.betas = VectorFrom(Member(j, "betas", source), source, "betas", -1);
  gt.params.transl = VectorFrom(Member(j, "transl", source), source, "transl", 3);
  gt.keypoints = PointsFrom(Member(j, "keypoints3d", source), source, "keypoints3d", 21);
  gt.joints = PointsFrom(Member(j, "joints3d", source), source, "joints3d", 16);
  gt.vertices = PointsFrom(Member(j, "vertices", source), source, "vertices", -1);
  if (j.contains("objects")) {
    const json& objects = j["objects"];
    if (!objects.is_array())
      throw InputError(source, "objects", "an array", objects.dump());
    for (size_t i = 0; i < objects.size(); ++i) {
      const std::string where = "objects[" + std::to_string(i) + "].";
      ObjectGroundTruth o;
      o.kind = String(objects[i], "kind", source, where);
      o.size = VectorFrom(Member(objects[i], "size", source, where), source,
                          where + "size", 3);
      const json& pose = Member(objects[i], "world_from_object", source, where);
      const Eigen::VectorXd q = VectorFrom(Member(pose, "rotation_xyzw", source, where),
                                           source, where + "rotation_xyzw", 4);
      const Eigen::VectorXd t = VectorFrom(Member(pose, "translation", source, where),
                                           source, where + "translation", 3);
      if (!(q.norm() > 0.5))
        throw InputError(source, where + "rotation_xyzw", "a unit quaternion");
      o.world_from_object = Rigid3(Eigen::Quaterniond(q[3], q[0], q[1], q[2]), t);
      gt.objects.push_back(o);
    }
  }
  return gt;
}

}  // namespace handlabel
