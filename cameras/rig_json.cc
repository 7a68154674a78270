#include "cameras/rig_json.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "core/json_util.h"
#include "geometry/camera_models.h"

namespace handlabel {
namespace {

using nlohmann::json;

const json& Member(const json& object, const char* key, const std::string& source,
                   const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end()) {
    throw InputError(source, where + key, "a value", "missing");
  }
  return *it;
}

std::vector<double> NumberArray(const json& value, size_t expected_size,
                                const std::string& source, const std::string& field) {
  if (!value.is_array())
    throw InputError(source, field, "an array of numbers", value.dump());
  if (expected_size > 0 && value.size() != expected_size) {
    throw InputError(source, field, std::to_string(expected_size) + " numbers",
                     std::to_string(value.size()));
  }
  std::vector<double> out;
  for (const json& v : value) {
    if (!v.is_number()) throw InputError(source, field, "numbers", v.dump());
    out.push_back(v.get<double>());
    if (!std::isfinite(out.back())) throw InputError(source, field, "finite numbers");
  }
  return out;
}

// An image side as written: any JSON number, range-checked before narrowing.
int ImageSide(const json& value, const std::string& source, const std::string& field) {
  if (!value.is_number_integer()) {
    throw InputError(source, field, "a positive integer", value.dump());
  }
  const long double side = value.is_number_unsigned()
                               ? static_cast<long double>(value.get<uint64_t>())
                               : static_cast<long double>(value.get<int64_t>());
  return CheckedImageSide(side, source, field);
}

RigCamera CameraFromJson(const json& j, const std::string& source,
                         const std::string& where) {
  if (!j.is_object()) throw InputError(source, where, "an object", j.dump());
  RejectUnknownKeys(j, {"name", "model", "width", "height", "params", "cam_from_world"},
                    source, where + ".");
  RigCamera cam;
  const json& name = Member(j, "name", source, where + ".");
  if (!name.is_string() || name.get<std::string>().empty()) {
    throw InputError(source, where + ".name", "a non-empty string", name.dump());
  }
  cam.name = name.get<std::string>();
  const std::string at = where + "(" + cam.name + ").";
  const json& model = Member(j, "model", source, at);
  if (!model.is_string())
    throw InputError(source, at + "model", "a model name", model.dump());
  const CameraModelId model_id =
      CameraModelFromName(model.get<std::string>(), source + ": " + at + "model");
  const int width = ImageSide(Member(j, "width", source, at), source, at + "width");
  const int height = ImageSide(Member(j, "height", source, at), source, at + "height");
  const std::vector<double> params = NumberArray(
      Member(j, "params", source, at), NumCameraParams(model_id), source, at + "params");
  cam.camera = Camera(model_id, width, height, params, source + ": " + where);

  const json& pose = Member(j, "cam_from_world", source, at);
  if (!pose.is_object()) {
    throw InputError(source, at + "cam_from_world", "an object", pose.dump());
  }
  const std::string pose_at = at + "cam_from_world.";
  RejectUnknownKeys(pose, {"rotation_xyzw", "translation"}, source, pose_at);
  const std::vector<double> q =
      NumberArray(Member(pose, "rotation_xyzw", source, pose_at), 4, source,
                  pose_at + "rotation_xyzw");
  const std::vector<double> t = NumberArray(Member(pose, "translation", source, pose_at),
                                            3, source, pose_at + "translation");
  const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
  const double norm = rotation.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    throw InputError(source, pose_at + "rotation_xyzw", "a unit quaternion",
                     "norm " + std::to_string(norm));
  }
  cam.cam_from_world = Rigid3(rotation, Eigen::Vector3d(t[0], t[1], t[2]));
  CheckPlausibleCamera(cam, source, at);
  return cam;
}

}  // namespace

int CheckedImageSide(long double value, const std::string& source,
                     const std::string& field, const CameraLimits& limits) {
  if (!(value >= 1 && value <= static_cast<long double>(limits.max_image_side)) ||
      value != std::floor(value)) {
    std::ostringstream got;
    got.precision(20);
    got << value;
    throw InputError(
        source, field,
        "a whole number of pixels in [1, " + std::to_string(limits.max_image_side) + "]",
        got.str());
  }
  return static_cast<int>(value);
}

void CheckPlausibleCamera(const RigCamera& cam, const std::string& source,
                          const std::string& where, const CameraLimits& limits) {
  const Camera& c = cam.camera;
  const std::vector<double>& p = c.params();
  const Intrinsics<double> in = UnpackIntrinsics(c.model(), p.data());
  const double side = std::max(c.width(), c.height());
  const auto fail = [&](const std::string& field, const std::string& expected,
                        double got) {
    std::ostringstream text;
    text << got;
    throw InputError(source, where + field, expected, text.str());
  };
  const double max_focal = limits.max_focal_per_side * side;
  for (const double f : {in.fx, in.fy}) {
    if (!(f > 0 && f <= max_focal)) {
      fail("params (focal length)",
           "a focal length in (0, " + std::to_string(max_focal) + "] pixels", f);
    }
  }
  const double m = limits.max_principal_offset;
  if (!(in.cx >= -m * c.width() && in.cx <= (1 + m) * c.width())) {
    fail("params (cx)",
         "a principal point x near the image (width " + std::to_string(c.width()) + ")",
         in.cx);
  }
  if (!(in.cy >= -m * c.height() && in.cy <= (1 + m) * c.height())) {
    fail("params (cy)",
         "a principal point y near the image (height " + std::to_string(c.height()) + ")",
         in.cy);
  }
  for (const double d : in.d) {
    if (!(std::abs(d) <= limits.max_distortion)) {
      fail("params (distortion)",
           "distortion coefficients within +-" + std::to_string(limits.max_distortion),
           d);
    }
  }
  const Eigen::Vector3d& t = cam.cam_from_world.translation;
  for (int k = 0; k < 3; ++k) {
    if (!(std::abs(t[k]) <= limits.max_translation_m)) {
      fail("cam_from_world.translation",
           "metres within +-" + std::to_string(limits.max_translation_m), t[k]);
    }
  }
}

Rig RigFromJson(const json& j, const std::string& source, RigFileInfo* info) {
  if (!j.is_object())
    throw InputError(source, "(top level)", "a JSON object", j.type_name());
  RejectUnknownKeys(j, {"format", "version", "world", "cameras"}, source);
  const json& format = Member(j, "format", source, "");
  if (format != "handlabel-rig") {
    throw InputError(source, "format", "\"handlabel-rig\"", format.dump());
  }
  const json& version = Member(j, "version", source, "");
  if (!version.is_number_integer() || version.get<int>() != kRigJsonVersion) {
    throw InputError(source, "version", std::to_string(kRigJsonVersion) + " (this build)",
                     version.dump());
  }
  if (info) {
    info->world.clear();
    if (const auto it = j.find("world"); it != j.end()) {
      if (!it->is_string()) throw InputError(source, "world", "a string", it->dump());
      info->world = it->get<std::string>();
    }
  }
  const json& cameras = Member(j, "cameras", source, "");
  if (!cameras.is_array() || cameras.empty()) {
    throw InputError(source, "cameras", "a non-empty array", cameras.dump());
  }
  Rig rig;
  for (size_t i = 0; i < cameras.size(); ++i) {
    RigCamera cam =
        CameraFromJson(cameras[i], source, "cameras[" + std::to_string(i) + "]");
    if (rig.IndexOf(cam.name) >= 0) {
      throw InputError(source, "cameras[" + std::to_string(i) + "].name", "unique names",
                       "'" + cam.name + "' twice");
    }
    rig.Add(std::move(cam));
  }
  return rig;
}

json RigToJson(const Rig& rig, const RigFileInfo& info) {
  json cameras = json::array();
  for (const RigCamera& c : rig.cameras()) {
    const Eigen::Quaterniond& q = c.cam_from_world.rotation;
    const Eigen::Vector3d& t = c.cam_from_world.translation;
    cameras.push_back({{"name", c.name},
                       {"model", CameraModelName(c.camera.model())},
                       {"width", c.camera.width()},
                       {"height", c.camera.height()},
                       {"params", c.camera.params()},
                       {"cam_from_world",
                        {{"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
                         {"translation", {t.x(), t.y(), t.z()}}}}});
  }
  json j = {{"format", "handlabel-rig"}, {"version", kRigJsonVersion}};
  if (!info.world.empty()) j["world"] = info.world;
  j["cameras"] = std::move(cameras);
  return j;
}

Rig ReadRigJson(const std::string& path, RigFileInfo* info) {
  return RigFromJson(ReadJsonFileStrict(path), path, info);
}

void WriteRigJson(const Rig& rig, const std::string& path, const RigFileInfo& info) {
  std::ofstream out(path);
  if (!out) throw InputError(path, "(file)", "a writable path", "cannot open");
  out << RigToJson(rig, info).dump(2) << "\n";
  out.close();
  if (!out) throw InputError(path, "(file)", "a successful write", "write failed");
}

}  // namespace handlabel
