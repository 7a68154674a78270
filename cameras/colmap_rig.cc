#include "cameras/colmap_rig.h"

#include <algorithm>
#include <limits>
#include <set>

#include "cameras/rig_json.h"
#include "core/errors.h"

namespace handlabel {

std::string CameraNameFromImageName(const std::string& image_name) {
  static const char* const kExtensions[] = {".png", ".jpg", ".jpeg",
                                            ".bmp", ".tif", ".tiff"};
  const size_t dot = image_name.rfind('.');
  if (dot == std::string::npos || image_name.find('/', dot) != std::string::npos) {
    return image_name;
  }
  std::string ext = image_name.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  for (const char* known : kExtensions) {
    if (ext == known) return image_name.substr(0, dot);
  }
  return image_name;
}

Rig RigFromColmap(const ColmapModel& model, const std::string& source) {
  if (model.images.empty()) {
    throw InputError(source, "images", "at least one registered image", "none");
  }
  std::vector<std::string> names;
  std::set<std::string> folders;
  bool all_in_folders = true;
  for (const auto& [id, image] : model.images) {
    names.push_back(CameraNameFromImageName(image.name));
    const size_t slash = names.back().find('/');
    if (slash == std::string::npos || slash == 0) {
      all_in_folders = false;
    } else {
      folders.insert(names.back().substr(0, slash));
    }
  }
  if (all_in_folders && folders.size() == names.size()) {
    for (std::string& name : names) name = name.substr(0, name.find('/'));
  }
  Rig rig;
  size_t i = 0;
  for (const auto& [id, image] : model.images) {
    const std::string where = "image " + std::to_string(id) + " (" + image.name + ")";
    const auto cam = model.cameras.find(image.camera_id);
    if (cam == model.cameras.end()) {
      throw InputError(source, where + " CAMERA_ID", "an id listed in cameras",
                       std::to_string(image.camera_id));
    }
    const uint64_t max_size = std::numeric_limits<int>::max();
    if (cam->second.width > max_size || cam->second.height > max_size) {
      throw InputError(source, "camera " + std::to_string(cam->first) + " WIDTH/HEIGHT",
                       "an image size below 2^31", "too large");
    }
    RigCamera rc;
    rc.name = names[i++];
    rc.camera = Camera(cam->second.model, static_cast<int>(cam->second.width),
                       static_cast<int>(cam->second.height), cam->second.params,
                       source + ": camera " + std::to_string(cam->first));
    rc.cam_from_world = image.cam_from_world;
    CheckPlausibleCamera(rc, source, "camera " + std::to_string(cam->first) + " ");
    if (rig.IndexOf(rc.name) >= 0) {
      throw InputError(source, where + " NAME", "one image per camera name",
                       "'" + rc.name + "' twice");
    }
    rig.Add(std::move(rc));
  }
  return rig;
}

ColmapModel ColmapFromRig(const Rig& rig) {
  ColmapModel model;
  for (size_t i = 0; i < rig.size(); ++i) {
    const RigCamera& rc = rig[i];
    const uint32_t id = static_cast<uint32_t>(i + 1);
    ColmapCamera cam;
    cam.id = id;
    cam.model = rc.camera.model();
    cam.width = static_cast<uint64_t>(rc.camera.width());
    cam.height = static_cast<uint64_t>(rc.camera.height());
    cam.params = rc.camera.params();
    model.cameras[id] = cam;
    ColmapImage image;
    image.id = id;
    image.camera_id = id;
    image.name = rc.name;
    image.cam_from_world = rc.cam_from_world;
    model.images[id] = image;
  }
  return model;
}

}  // namespace handlabel
