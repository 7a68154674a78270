#include "capture/capture_format.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/json_util.h"
#include "core/text.h"
#include "hand/hand_params_json.h"

namespace handlabel {
namespace {

using nlohmann::json;

// A non-empty list of non-empty strings.
std::vector<std::string> StringList(const json& j, const char* key,
                                    const std::string& source) {
  const json& v = JsonMember(j, key, source);
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
  RejectUnknownKeys(j,
                    {"format", "version", "rig", "colmap", "cameras", "frames", "files",
                     "depth_unit_m", "world", "hand_side", "generator"},
                    source);
  CaptureManifest m;
  if (JsonString(j, "format", source) != "handlabel-capture") {
    throw InputError(source, "format", "\"handlabel-capture\"",
                     JsonMember(j, "format", source).dump());
  }
  const json& version = JsonMember(j, "version", source);
  if (!version.is_number_integer() || version.get<int>() != kCaptureFormatVersion) {
    throw InputError(
        source, "version",
        std::to_string(kCaptureFormatVersion) + " (this build reads only it)",
        version.dump());
  }
  m.rig_file = JsonString(j, "rig", source);
  if (j.contains("colmap")) m.colmap_dir = JsonString(j, "colmap", source);
  m.cameras = StringList(j, "cameras", source);
  for (size_t c = 0; c < m.cameras.size(); ++c) {
    CheckCameraName(m.cameras[c], source, "cameras[" + std::to_string(c) + "]");
  }
  m.frames = StringList(j, "frames", source);
  const json& files = JsonMember(j, "files", source);
  if (!files.is_object())
    throw InputError(source, "files", "an object of patterns", files.dump());
  for (const auto& [kind, pattern] : files.items()) {
    if (!pattern.is_string()) {
      throw InputError(source, "files." + kind, "a path pattern string", pattern.dump());
    }
    m.files[kind] = pattern.get<std::string>();
  }
  if (j.contains("depth_unit_m")) {
    m.depth_unit_m = JsonNumber(j["depth_unit_m"], source, "depth_unit_m");
    if (!(m.depth_unit_m > 0)) throw InputError(source, "depth_unit_m", "> 0");
  }
  if (j.contains("world")) m.world = JsonString(j, "world", source);
  if (j.contains("hand_side")) {
    m.hand_side = JsonString(j, "hand_side", source);
    ParseHandSide(m.hand_side, source, "hand_side");  // refuses other spellings
  }
  if (j.contains("generator")) m.generator = j["generator"];
  return m;
}

std::string ExpandPattern(const std::string& pattern, const std::string& camera,
                          const std::string& frame) {
  // One pass over the pattern: a value is never expanded again (a camera named
  // "{frame}" made two cameras share one path before names were checked).
  std::string out;
  for (size_t at = 0; at < pattern.size();) {
    if (pattern.compare(at, 8, "{camera}") == 0) {
      out += camera;
      at += 8;
    } else if (pattern.compare(at, 7, "{frame}") == 0) {
      out += frame;
      at += 7;
    } else {
      out += pattern[at++];
    }
  }
  return out;
}

void CheckCameraName(const std::string& name, const std::string& source,
                     const std::string& field) {
  const bool usable =
      !name.empty() && name != "." && name != ".." &&
      std::none_of(name.begin(), name.end(), [](char c) {
        const auto u = static_cast<unsigned char>(c);
        return u <= 0x20 || u == 0x7f || c == '/' || c == '\\' || c == '{' || c == '}';
      });
  if (!usable) {
    throw InputError(source, field,
                     "a camera name usable as a folder name, in file patterns and in "
                     "COLMAP's text model: no spaces, control characters, '/', '\\', "
                     "'{' or '}', not '.' or '..'",
                     json(name).dump());
  }
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
      kp.push_back({JsonNumberOrNull(v.keypoints.uv_px(k, 0)),
                    JsonNumberOrNull(v.keypoints.uv_px(k, 1))});
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
  // "detector", "hand" and "tracking" (and the per-view fields after "hand_pixels")
  // are what `handlabel detect` records beside the keypoints (docs/detector.md).
  RejectUnknownKeys(
      j, {"frame", "views", "detector", "hand", "tracking", "other_hands", "max_hands"},
      source);
  const json& views = JsonMember(j, "views", source);
  if (!views.is_array()) throw InputError(source, "views", "an array", views.dump());
  std::vector<ViewKeypoints> out;
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string where = "views[" + std::to_string(i) + "].";
    const json& jv = views[i];
    RejectUnknownKeys(jv,
                      {"camera", "keypoints", "visibility", "confidence", "status",
                       "hand_pixels", "detected", "palm_candidates", "source", "presence",
                       "handedness", "median_reprojection_px", "reason", "region"},
                      source, where);
    ViewKeypoints v;
    v.camera = JsonString(jv, "camera", source, where);
    const json& kp = JsonMember(jv, "keypoints", source, where);
    if (!kp.is_array() || kp.size() != kNumHandKeypoints) {
      throw InputError(source, where + "keypoints", "21 [x, y] pairs",
                       kp.dump().substr(0, 80));
    }
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!kp[k].is_array() || kp[k].size() != 2) {
        throw InputError(source, where + "keypoints", "[x, y] or [null, null]",
                         kp[k].dump());
      }
      v.keypoints.uv_px(k, 0) =
          JsonNumber(kp[k][0], source, where + "keypoints", JsonNull::kAsNan);
      v.keypoints.uv_px(k, 1) =
          JsonNumber(kp[k][1], source, where + "keypoints", JsonNull::kAsNan);
    }
    v.visibility.fill(-1);
    v.keypoints.confidence.setOnes();
    if (jv.contains("visibility")) {
      const Eigen::VectorXd vis =
          JsonVector(jv["visibility"], source, where + "visibility", 21);
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
          JsonVector(jv["confidence"], source, where + "confidence", 21);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        if (!(c[k] >= 0 && c[k] <= 1)) {
          throw InputError(source, where + "confidence[" + std::to_string(k) + "]",
                           "a confidence in [0, 1]", std::to_string(c[k]));
        }
      }
      v.keypoints.confidence = c;
    }
    if (jv.contains("status")) v.status = JsonString(jv, "status", source, where);
    if (jv.contains("hand_pixels")) {
      v.hand_pixels =
          static_cast<int>(JsonNumber(jv["hand_pixels"], source, where + "hand_pixels"));
    }
    out.push_back(v);
  }
  return out;
}

namespace {

// A position given in a view must lie within the camera's image widened by its size on
// every side: detectors place a hand's keypoints a little outside the image at most.
void CheckPositionsNearImage(const ViewKeypoints& view, const RigCamera& camera,
                             const std::string& source, const std::string& where) {
  const double w = camera.camera.width(), h = camera.camera.height();
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const double u = view.keypoints.uv_px(k, 0), v = view.keypoints.uv_px(k, 1);
    if ((std::isnan(u) && std::isnan(v)) || view.visibility[k] == 0) continue;
    if (u >= -w && u <= 2 * w && v >= -h && v <= 2 * h) continue;  // NaN fails too
    char got[80];
    std::snprintf(got, sizeof(got), "[%g, %g]", u, v);
    throw InputError(
        source, where + "keypoints[" + std::to_string(k) + "]",
        "a pixel position near the " + std::to_string(camera.camera.width()) + "x" +
            std::to_string(camera.camera.height()) + " image of camera " + camera.name +
            " (x in [" + FormatNumber(-w) + ", " + FormatNumber(2 * w) + "], y in [" +
            FormatNumber(-h) + ", " + FormatNumber(2 * h) + "]) or [null, null]",
        got);
  }
}

// Frame ids of dataset inputs are relative to the job's input folder ("0000" with the
// sequence's folder, "ABF1/0000" with the split's): one file serves both.
bool SameFrame(const std::string& a, const std::string& b) {
  const auto ends_with = [](const std::string& id, const std::string& tail) {
    return id.size() > tail.size() && id[id.size() - tail.size() - 1] == '/' &&
           id.compare(id.size() - tail.size(), tail.size(), tail) == 0;
  };
  return a == b || ends_with(a, b) || ends_with(b, a);
}

}  // namespace

std::vector<std::optional<ViewKeypoints>> FrameKeypointsFromJson(
    const json& j, const std::string& source, const std::string& frame, const Rig& rig) {
  const std::vector<ViewKeypoints> views = ViewKeypointsFromJson(j, source);
  if (j.contains("frame") &&
      !(j["frame"].is_string() && SameFrame(j["frame"].get<std::string>(), frame))) {
    throw InputError(source, "frame",
                     "'" + frame +
                         "' (the frame this file is read for; a file of another "
                         "frame is not used)",
                     j["frame"].dump());
  }
  std::vector<std::optional<ViewKeypoints>> ordered(rig.size());
  for (size_t i = 0; i < views.size(); ++i) {
    const ViewKeypoints& view = views[i];
    const std::string where = "views[" + std::to_string(i) + "].";
    const int c = rig.IndexOf(view.camera);
    if (c < 0) {
      throw InputError(source, where + "camera", "a camera of the rig",
                       "'" + view.camera + "'");
    }
    if (ordered[c])
      throw InputError(source, where + "camera", "each camera once",
                       "'" + view.camera + "' again");
    CheckPositionsNearImage(view, rig[c], source, where);
    ordered[c] = view;
  }
  return ordered;
}

std::string DetectionsHandChoice::Describe() const {
  if (count <= 1 && max_hands <= 1) return "";
  return "hand " + std::to_string(index + 1) + " of " + std::to_string(count) +
         (side.empty() ? "" : " (" + side + ")");
}

namespace {

// A hand record's "hand" {found, side}: whether it was found with side `side`; its side
// into `side_name` ("" when the record has no "hand").
bool FoundWithSide(const json& record, const std::string& wanted,
                   const std::string& source, const std::string& where,
                   std::string* side_name) {
  side_name->clear();
  if (!record.contains("hand")) return false;
  const json& hand = JsonMember(record, "hand", source, where);
  *side_name = JsonString(hand, "side", source, where + "hand.");
  const json& found = JsonMember(hand, "found", source, where + "hand.");
  if (!found.is_boolean())
    throw InputError(source, where + "hand.found", "true or false", found.dump());
  return found.get<bool>() && *side_name == wanted;
}

}  // namespace

DetectionsHandChoice ChooseDetectionsHand(const json& file, std::optional<HandSide> side,
                                          const std::string& source) {
  DetectionsHandChoice choice;
  if (!side) {  // a reader of the first hand (contact sheets)
    choice.record = file;
    return choice;
  }
  const std::string wanted = HandSideName(*side);
  const bool first_matches = FoundWithSide(file, wanted, source, "", &choice.side);
  const json* others = file.contains("other_hands") ? &file["other_hands"] : nullptr;
  if (others && !others->is_array())
    throw InputError(source, "other_hands", "an array of hands", others->dump());
  choice.count = 1 + (others ? static_cast<int>(others->size()) : 0);
  if (file.contains("max_hands")) {
    const json& looked_for = file["max_hands"];
    if (!looked_for.is_number_integer() || looked_for.get<int>() < 1)
      throw InputError(source, "max_hands", "a whole number >= 1", looked_for.dump());
    choice.max_hands = looked_for.get<int>();
  }
  if (first_matches) {
    choice.record = file;
    return choice;
  }
  for (size_t k = 0; others && k < others->size(); ++k) {
    const std::string where = "other_hands[" + std::to_string(k) + "].";
    std::string other_side;
    if (!FoundWithSide((*others)[k], wanted, source, where, &other_side)) continue;
    choice.record = (*others)[k];
    if (file.contains("frame")) choice.record["frame"] = file["frame"];
    choice.index = static_cast<int>(k) + 1;
    choice.side = other_side;
    return choice;
  }
  if (choice.max_hands > 1) {
    // Several hands were looked for and none of them is this side's: another hand is not
    // the one the capture is about.
    throw InputError(source, "hand",
                     "a found " + wanted +
                         " hand (the capture's side) among the hands "
                         "`detect --max-hands " +
                         std::to_string(choice.max_hands) + "` found",
                     std::to_string(choice.count) + " hand(s), none " + wanted);
  }
  choice.record = file;
  return choice;
}

json GroundTruthToJson(const std::string& frame, const HandGroundTruth& gt) {
  json j;
  j["frame"] = frame;
  j["hand_model"] = gt.hand_model;
  j["side"] = gt.side;
  j["pose_kind"] = gt.pose_kind;
  j.update(JsonHandParams(gt.params));  // the parameters sit at the top level
  j["keypoints3d"] = JsonPoints(gt.keypoints);
  j["joints3d"] = JsonPoints(gt.joints);
  j["vertices"] = JsonPoints(gt.vertices);
  j["objects"] = json::array();
  for (const ObjectGroundTruth& o : gt.objects) {
    const Eigen::Quaterniond& q = o.world_from_object.rotation;
    j["objects"].push_back(
        {{"kind", o.kind},
         {"size", JsonArray(o.size)},
         {"world_from_object",
          {{"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
           {"translation", JsonArray(o.world_from_object.translation)}}}});
  }
  return j;
}

HandGroundTruth GroundTruthFromJson(const json& j, const std::string& source) {
  RejectUnknownKeys(
      j,
      {"frame", "hand_model", "side", "pose_kind", "global_orient", "hand_pose", "betas",
       "transl", "keypoints3d", "joints3d", "vertices", "objects"},
      source);
  HandGroundTruth gt;
  gt.hand_model = JsonString(j, "hand_model", source);
  gt.side = JsonString(j, "side", source);
  gt.pose_kind = JsonString(j, "pose_kind", source);
  gt.params = HandParamsFromJson(j, source);
  gt.keypoints =
      JsonPointList(JsonMember(j, "keypoints3d", source), source, "keypoints3d", 21);
  gt.joints = JsonPointList(JsonMember(j, "joints3d", source), source, "joints3d", 16);
  gt.vertices = JsonPointList(JsonMember(j, "vertices", source), source, "vertices", -1);
  if (j.contains("objects")) {
    const json& objects = j["objects"];
    if (!objects.is_array())
      throw InputError(source, "objects", "an array", objects.dump());
    for (size_t i = 0; i < objects.size(); ++i) {
      const std::string where = "objects[" + std::to_string(i) + "].";
      ObjectGroundTruth o;
      o.kind = JsonString(objects[i], "kind", source, where);
      o.size = JsonVector(JsonMember(objects[i], "size", source, where), source,
                          where + "size", 3);
      const json& pose = JsonMember(objects[i], "world_from_object", source, where);
      const Eigen::VectorXd q =
          JsonVector(JsonMember(pose, "rotation_xyzw", source, where), source,
                     where + "rotation_xyzw", 4);
      const Eigen::VectorXd t = JsonVector(JsonMember(pose, "translation", source, where),
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
