#include "geometry/camera_models.h"

#include "core/errors.h"

namespace handlabel {
namespace {

struct ModelInfo {
  CameraModelId id;
  const char* name;
  int num_params;
};

constexpr ModelInfo kModels[] = {
    {CameraModelId::kSimplePinhole, "SIMPLE_PINHOLE", 3},
    {CameraModelId::kPinhole, "PINHOLE", 4},
    {CameraModelId::kSimpleRadial, "SIMPLE_RADIAL", 4},
    {CameraModelId::kRadial, "RADIAL", 5},
    {CameraModelId::kOpenCV, "OPENCV", 8},
    {CameraModelId::kOpenCVFisheye, "OPENCV_FISHEYE", 8},
    {CameraModelId::kFullOpenCV, "FULL_OPENCV", 12},
};

const ModelInfo& Info(CameraModelId model) {
  for (const ModelInfo& info : kModels) {
    if (info.id == model) return info;
  }
  HL_CHECK(false, "camera model id " + std::to_string(static_cast<int>(model)));
}

std::string KnownModels() {
  std::string names;
  for (const ModelInfo& info : kModels) {
    names += (names.empty() ? "" : ", ") + std::string(info.name);
  }
  return names;
}

}  // namespace

int NumCameraParams(CameraModelId model) { return Info(model).num_params; }
std::string CameraModelName(CameraModelId model) { return Info(model).name; }

CameraModelId CameraModelFromName(const std::string& name, const std::string& source) {
  for (const ModelInfo& info : kModels) {
    if (name == info.name) return info.id;
  }
  throw InputError(source, "model", "one of " + KnownModels(), "'" + name + "'");
}

CameraModelId CameraModelFromId(int id, const std::string& source) {
  for (const ModelInfo& info : kModels) {
    if (static_cast<int>(info.id) == id) return info.id;
  }
  throw InputError(source, "model_id", "a camera model id 0-6 (" + KnownModels() + ")",
                   std::to_string(id));
}

}  // namespace handlabel
