#include "capture/capture_manifest_file.h"

#include <filesystem>
#include <fstream>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace handlabel {

std::string CaptureManifestPath(const std::string& dir) {
  return (std::filesystem::path(dir) / kCaptureManifestFile).string();
}

CaptureManifest ReadCaptureManifest(const std::string& dir,
                                    const std::string& how_to_make) {
  const std::string path = CaptureManifestPath(dir);
  std::ifstream in(path);
  if (!in) {
    throw InputError(path, "file", "a capture manifest (" + how_to_make + ")", "missing");
  }
  try {
    return ManifestFromJson(nlohmann::json::parse(in), path);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "content", "valid JSON", e.what());
  }
}

void WriteCaptureManifest(const std::string& dir, const CaptureManifest& manifest) {
  WriteFileAtomically(CaptureManifestPath(dir), ManifestToJson(manifest).dump(2) + "\n");
}

}  // namespace handlabel
