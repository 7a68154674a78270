#include "cameras/colmap_model.h"

#include <filesystem>

#include "core/errors.h"

namespace handlabel {

ColmapModel ReadColmapModel(const std::string& dir) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir)) {
    throw InputError(dir, "(folder)", "a COLMAP sparse model folder", "not a folder");
  }
  if (fs::exists(fs::path(dir) / "cameras.bin")) return ReadColmapBinary(dir);
  if (fs::exists(fs::path(dir) / "cameras.txt")) return ReadColmapText(dir);
  throw InputError(dir, "cameras.bin / cameras.txt", "a COLMAP model (cameras file)",
                   "neither exists");
}

ColmapModel ReadColmapModel(const std::string& dir, ColmapFormat format) {
  return format == ColmapFormat::kBinary ? ReadColmapBinary(dir) : ReadColmapText(dir);
}

void WriteColmapModel(const ColmapModel& model, const std::string& dir,
                      ColmapFormat format) {
  if (format == ColmapFormat::kBinary) {
    WriteColmapBinary(model, dir);
  } else {
    WriteColmapText(model, dir);
  }
}

void CheckColmapModel(const ColmapModel& model, const std::string& source) {
  for (const auto& [id, image] : model.images) {
    if (!model.cameras.count(image.camera_id)) {
      throw InputError(source, "image " + std::to_string(id) + " CAMERA_ID",
                       "an id listed in cameras", std::to_string(image.camera_id));
    }
    if (image.points2D.size() != image.point3D_ids.size()) {
      throw InputError(source, "image " + std::to_string(id) + " POINTS2D",
                       "one POINT3D_ID per point", "mismatched counts");
    }
    for (uint64_t p : image.point3D_ids) {
      if (p != kColmapNoPoint3D && !model.points3D.empty() && !model.points3D.count(p)) {
        throw InputError(source, "image " + std::to_string(id) + " POINT3D_ID",
                         "an id listed in points3D", std::to_string(p));
      }
    }
  }
  for (const auto& [id, point] : model.points3D) {
    for (const ColmapTrackElement& e : point.track) {
      const auto it = model.images.find(e.image_id);
      if (it == model.images.end()) {
        throw InputError(source, "point3D " + std::to_string(id) + " TRACK IMAGE_ID",
                         "an id listed in images", std::to_string(e.image_id));
      }
      if (e.point2D_idx >= it->second.points2D.size()) {
        throw InputError(source, "point3D " + std::to_string(id) + " TRACK POINT2D_IDX",
                         "an index below " + std::to_string(it->second.points2D.size()),
                         std::to_string(e.point2D_idx));
      }
    }
  }
}

}  // namespace handlabel
