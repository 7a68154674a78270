#pragma once
// The project's own rig file (JSON), version 1:
//
//   {
//     "format": "handlabel-rig",
//     "version": 1,
//     "world": "camera:cam0",            // optional free text: what the world frame is
//     "cameras": [
//       {"name": "cam0", "model": "OPENCV", "width": 640, "height": 480,
//        "params": [fx, fy, cx, cy, k1, k2, p1, p2],          // COLMAP order
//        "cam_from_world": {"rotation_xyzw": [x, y, z, w],    // Hamilton, unit
//                           "translation": [tx, ty, tz]}}     // metres
//     ]
//   }
//
// cam_from_world maps world points into the camera (OpenCV axes); the camera centre
// is -R^T t. Readers reject unknown versions and name file and field on every error.

#include <nlohmann/json.hpp>
#include <string>

#include "core/rig.h"

namespace handlabel {

inline constexpr int kRigJsonVersion = 1;

// What a rig file holds beyond the cameras.
struct RigFileInfo {
  std::string world;  // free text, "" if absent
};

Rig RigFromJson(const nlohmann::json& json, const std::string& source,
                RigFileInfo* info = nullptr);
nlohmann::json RigToJson(const Rig& rig, const RigFileInfo& info = {});

// Throws InputError for unreadable files, bad JSON or bad fields.
Rig ReadRigJson(const std::string& path, RigFileInfo* info = nullptr);
// Writes with full double precision (values round-trip exactly).
void WriteRigJson(const Rig& rig, const std::string& path, const RigFileInfo& info = {});

}  // namespace handlabel
