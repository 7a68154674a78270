#include "geometry/rig.h"

#include "core/errors.h"

namespace handlabel {

void Rig::Add(RigCamera camera) {
  if (camera.name.empty()) throw InputError("rig", "name", "a non-empty camera name");
  if (IndexOf(camera.name) >= 0) {
    throw InputError("rig", "name", "unique camera names", "'" + camera.name + "' twice");
  }
  cameras_.push_back(std::move(camera));
}

int Rig::IndexOf(const std::string& name) const {
  for (size_t i = 0; i < cameras_.size(); ++i) {
    if (cameras_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

const RigCamera& Rig::Find(const std::string& name) const {
  const int index = IndexOf(name);
  if (index < 0) {
    std::string known;
    for (const RigCamera& c : cameras_) known += (known.empty() ? "" : ", ") + c.name;
    throw InputError("rig", "camera", "one of [" + known + "]", "'" + name + "'");
  }
  return cameras_[index];
}

void Rig::SetWorldToCamera(size_t master_index) {
  HL_CHECK(master_index < cameras_.size(), "master index out of range");
  const Rigid3 old_from_new = cameras_[master_index].cam_from_world.Inverse();
  for (RigCamera& c : cameras_) c.cam_from_world = c.cam_from_world * old_from_new;
}

}  // namespace handlabel
