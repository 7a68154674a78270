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
// is -R^T t. Readers reject unknown versions, unknown or repeated keys, sizes and
// numbers outside CameraLimits, and name file and field on every error.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/rig.h"

namespace handlabel {

inline constexpr int kRigJsonVersion = 1;

// Plausible ranges for every camera number read from a file: a value outside them is
// a typo or a unit mistake, never a camera (checked before any narrowing).
struct CameraLimits {
  int64_t max_image_side = 65536;      // pixels, width and height
  double max_focal_per_side = 1000.0;  // focal length / larger image side (telephoto)
  double max_principal_offset = 1.0;   // cx, cy outside the image by this share of it
  double max_distortion = 1e4;         // |k|, |p| of any distortion coefficient
  double max_translation_m = 1e4;      // |cam_from_world.translation| components
};

// An image width or height in [1, limits.max_image_side]; throws InputError naming
// source and field (the value as read, before narrowing to int).
int CheckedImageSide(long double value, const std::string& source,
                     const std::string& field, const CameraLimits& limits = {});
// Throws InputError naming source and where + the field for an implausible focal
// length, principal point, distortion coefficient or translation.
void CheckPlausibleCamera(const RigCamera& camera, const std::string& source,
                          const std::string& where, const CameraLimits& limits = {});

// What a rig file holds beyond the cameras.
struct RigFileInfo {
  std::string world;  // free text, "" if absent
  // Per camera, the file its intrinsics and image size were read from when that is not
  // the rig file itself (DexYCB: calibration/intrinsics/<serial>_<W>x<H>.yml), so that
  // a size mismatch found later can name it; empty otherwise. Not written to JSON.
  std::vector<std::string> intrinsics_files;
};

Rig RigFromJson(const nlohmann::json& json, const std::string& source,
                RigFileInfo* info = nullptr);
nlohmann::json RigToJson(const Rig& rig, const RigFileInfo& info = {});

// Throws InputError for unreadable files, bad JSON or bad fields.
Rig ReadRigJson(const std::string& path, RigFileInfo* info = nullptr);
// Writes with full double precision (values round-trip exactly).
void WriteRigJson(const Rig& rig, const std::string& path, const RigFileInfo& info = {});

}  // namespace handlabel
