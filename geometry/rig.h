#pragma once
// A multi-camera rig: named cameras with intrinsics and cam_from_world extrinsics.
// The world frame is whatever the rig file defines (often a master camera).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"

namespace handlabel {

struct RigCamera {
  std::string name;
  Camera camera;
  Rigid3 cam_from_world;

  // Pixel of a world point; false if behind the camera.
  bool ProjectWorld(const Eigen::Vector3d& point_in_world, Eigen::Vector2d* uv) const {
    return camera.Project(cam_from_world * point_in_world, uv);
  }
  Eigen::Vector3d CenterInWorld() const { return cam_from_world.SourceOrigin(); }
};

class Rig {
 public:
  // Throws InputError if the name is empty or already used.
  void Add(RigCamera camera);
  size_t size() const { return cameras_.size(); }
  bool empty() const { return cameras_.empty(); }
  const RigCamera& operator[](size_t i) const { return cameras_[i]; }
  RigCamera& operator[](size_t i) { return cameras_[i]; }
  const std::vector<RigCamera>& cameras() const { return cameras_; }
  // -1 if absent.
  int IndexOf(const std::string& name) const;
  // Throws InputError listing the known names if absent.
  const RigCamera& Find(const std::string& name) const;
  // Re-expresses every extrinsic so that `new_world_from_old_world` becomes identity
  // at the given camera: cam_from_new_world = cam_from_old_world * old_from_new.
  void SetWorldToCamera(size_t master_index);

 private:
  std::vector<RigCamera> cameras_;
};

}  // namespace handlabel
