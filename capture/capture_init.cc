#include <algorithm>
#include <filesystem>

#include "cameras/colmap_model.h"
#include "cameras/colmap_rig.h"
#include "cameras/rig_json.h"
#include "capture/capture_import.h"
#include "capture/capture_manifest_file.h"
#include "core/errors.h"
#include "core/file_lock.h"
#include "core/text.h"
#include "core/version.h"
#include "hand/hand_model.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

// Camera names become folder names, pattern values and COLMAP tokens.
void CheckCameraNames(const Rig& rig, const std::string& source) {
  for (size_t c = 0; c < rig.size(); ++c) {
    CheckCameraName(rig[c].name, source, "cameras[" + std::to_string(c) + "] name");
  }
}

}  // namespace

void CaptureInitOptions::Check(const std::string& source) const {
  ParseHandSide(hand_side, source, "hand_side");
}

RigSpec ResolveRigSpec(const std::string& text, const std::string& flag) {
  const size_t colon = text.find(':');
  if (colon != std::string::npos) {
    const std::vector<std::string> formats = ReadableRigFormats();
    if (std::find(formats.begin(), formats.end(), text.substr(0, colon)) !=
        formats.end()) {
      return ParseRigSpec(text, flag);
    }
  }
  const fs::path path(text);
  if (fs::is_regular_file(path) && Lower(path.extension().string()) == ".json") {
    return {"json", text};
  }
  if (fs::is_directory(path)) {
    if (fs::is_regular_file(path / "rig.json")) {
      return {"json", (path / "rig.json").string()};
    }
    if (fs::exists(path / "cameras.bin") || fs::exists(path / "cameras.txt")) {
      return {"colmap", text};
    }
  }
  throw InputError(flag, "value",
                   "FORMAT:PATH (formats: " + Join(ReadableRigFormats(), ", ") +
                       "), a rig .json file, a folder holding rig.json (the output of "
                       "`calib board` / `calib colmap`) or a COLMAP model folder",
                   text);
}

void InitCapture(const Rig& rig, const RigFileInfo& rig_info, const std::string& out_dir,
                 const CaptureInitOptions& options) {
  options.Check("capture init options");
  if (rig.empty()) {
    throw InputError(options.rig_source, "cameras", "at least one camera", "none");
  }
  CheckCameraNames(rig, options.rig_source);
  const fs::path root(out_dir);
  if (fs::exists(root) && !fs::is_directory(root)) {
    throw InputError(out_dir, "--out", "a folder (or a path to create)",
                     "an existing file");
  }
  fs::create_directories(root);
  const FileLock writer = LockFolderForWriting(out_dir, "capture init", "--out", "");
  if (fs::exists(root / kCaptureManifestFile)) {
    if (!options.overwrite) {
      throw InputError(out_dir, "--out", "a folder without a capture (or --overwrite)",
                       "it already holds " + std::string(kCaptureManifestFile));
    }
    // The manifest goes first: a half-replaced folder is never a readable capture.
    fs::remove(root / kCaptureManifestFile);
    fs::remove_all(root / kImportImagesFolder);
  }
  CaptureManifest manifest;
  manifest.colmap_dir = "colmap";
  manifest.world = options.world.empty() ? rig_info.world : options.world;
  if (manifest.world.empty()) manifest.world = "as in " + options.rig_source;
  manifest.hand_side = options.hand_side;
  for (const RigCamera& cam : rig.cameras()) manifest.cameras.push_back(cam.name);
  manifest.files[kFileImage] = kImportImagePattern;
  manifest.generator = {{"tool", "handlabel capture init"},
                        {"handlabel_version", HandlabelVersion()},
                        {"rig", options.rig_source}};
  fs::create_directories(root / manifest.colmap_dir);
  RigFileInfo info;
  info.world = manifest.world;
  WriteRigJson(rig, (root / manifest.rig_file).string(), info);
  WriteColmapText(ColmapFromRig(rig), (root / manifest.colmap_dir).string());
  WriteCaptureManifest(out_dir, manifest);
}

}  // namespace handlabel
