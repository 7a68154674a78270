#pragma once
// A COLMAP sparse model (cameras, images, points3D) in memory, with readers and writers
// for COLMAP's text and binary formats (COLMAP 3.x layout, see docs/cameras.md).
//
// Poses: COLMAP stores the world-to-camera rotation as a Hamilton quaternion in the
// order (w, x, y, z) plus a translation; here it is held as a Rigid3 cam_from_world
// (Eigen coeffs x, y, z, w). Ids are kept as in the files (they need not be
// contiguous). Readers throw InputError naming the file, the record and the field.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "geometry/camera_models.h"
#include "geometry/rigid3.h"

namespace handlabel {

inline constexpr uint64_t kColmapNoPoint3D = UINT64_MAX;  // "-1" in the text format

struct ColmapCamera {
  uint32_t id = 0;
  CameraModelId model = CameraModelId::kPinhole;
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;  // COLMAP order, NumCameraParams(model) values
};

struct ColmapImage {
  uint32_t id = 0;
  Rigid3 cam_from_world;
  uint32_t camera_id = 0;
  std::string name;  // relative image path, e.g. "cam0/000000.png"
  std::vector<Eigen::Vector2d> points2D;
  std::vector<uint64_t> point3D_ids;  // one per point2D, kColmapNoPoint3D = none
};

struct ColmapTrackElement {
  uint32_t image_id = 0;
  uint32_t point2D_idx = 0;
};

struct ColmapPoint3D {
  uint64_t id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::array<uint8_t, 3> rgb = {0, 0, 0};
  double error = 0;
  std::vector<ColmapTrackElement> track;
};

struct ColmapModel {
  std::map<uint32_t, ColmapCamera> cameras;
  std::map<uint32_t, ColmapImage> images;
  std::map<uint64_t, ColmapPoint3D> points3D;
};

enum class ColmapFormat { kText, kBinary };

// Reads `dir`/cameras.{txt,bin}, images.*, points3D.* (points3D may be absent).
// kText/kBinary force a format; ReadColmapModel picks binary if cameras.bin exists,
// else text.
ColmapModel ReadColmapModel(const std::string& dir);
ColmapModel ReadColmapModel(const std::string& dir, ColmapFormat format);
// Writes the three files into an existing folder. Text uses 17 significant digits,
// so doubles round-trip exactly.
void WriteColmapModel(const ColmapModel& model, const std::string& dir,
                      ColmapFormat format);

// The format-specific halves of the above.
ColmapModel ReadColmapText(const std::string& dir);
ColmapModel ReadColmapBinary(const std::string& dir);
void WriteColmapText(const ColmapModel& model, const std::string& dir);
void WriteColmapBinary(const ColmapModel& model, const std::string& dir);

// Checks that every image's camera exists and that every track element points at an
// existing image/point2D; throws InputError naming `source` otherwise.
void CheckColmapModel(const ColmapModel& model, const std::string& source);

}  // namespace handlabel
