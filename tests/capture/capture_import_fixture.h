#pragma once
// A small rig and an empty capture made from it, for the capture import tests.

#include <string>

#include "capture/capture_import.h"
#include "geometry/rig.h"

namespace handlabel::testing {

inline constexpr int kWidth = 32;
inline constexpr int kHeight = 24;

// Cameras cam0, cam1, ... of kWidth x kHeight pixels, 10 cm apart.
inline Rig SmallRig(int cameras) {
  Rig rig;
  for (int c = 0; c < cameras; ++c) {
    RigCamera cam;
    cam.name = "cam" + std::to_string(c);
    cam.camera = Camera::Pinhole(40 + c, 41 + c, 15.5, 11.5, kWidth, kHeight);
    cam.cam_from_world.translation = Eigen::Vector3d(0.1 * c, 0, 0);
    rig.Add(cam);
  }
  return rig;
}

// `capture init` of SmallRig(cameras) into DIR/capture; returns that folder.
inline std::string InitSmallCapture(const std::string& dir, int cameras = 3) {
  const std::string capture = dir + "/capture";
  CaptureInitOptions init;
  init.rig_source = "test rig";
  InitCapture(SmallRig(cameras), {}, capture, init);
  return capture;
}

}  // namespace handlabel::testing
