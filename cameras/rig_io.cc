#include "cameras/rig_io.h"

#include <algorithm>
#include <filesystem>

#include "cameras/colmap_model.h"
#include "cameras/colmap_rig.h"
#include "cameras/dataset_calib.h"
#include "core/errors.h"
#include "core/text.h"

namespace handlabel {
namespace {

bool Contains(const std::vector<std::string>& items, const std::string& s) {
  return std::find(items.begin(), items.end(), s) != items.end();
}

}  // namespace

std::vector<std::string> ReadableRigFormats() {
  std::vector<std::string> formats = {"json", "colmap", "colmap-text", "colmap-bin"};
  for (const std::string& f : DatasetRigFormats()) formats.push_back(f);
  return formats;
}

std::vector<std::string> WritableRigFormats() {
  return {"json", "colmap", "colmap-text", "colmap-bin"};
}

RigSpec ParseRigSpec(const std::string& text, const std::string& flag) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0) {
    throw InputError(flag, "FORMAT:PATH",
                     "FORMAT:PATH with FORMAT one of " + Join(ReadableRigFormats()),
                     "'" + text + "'");
  }
  RigSpec spec{text.substr(0, colon), text.substr(colon + 1)};
  if (!Contains(ReadableRigFormats(), spec.format)) {
    throw InputError(flag, "FORMAT", "one of " + Join(ReadableRigFormats()),
                     "'" + spec.format + "'");
  }
  if (spec.path.empty())
    throw InputError(flag, "PATH", "a path after the ':'", "nothing");
  return spec;
}

Rig ReadRig(const RigSpec& spec, RigFileInfo* info) {
  if (info) *info = {};
  if (spec.format == "json") return ReadRigJson(spec.path, info);
  if (spec.format == "colmap" || spec.format == "colmap-text" ||
      spec.format == "colmap-bin") {
    const ColmapModel model = spec.format == "colmap" ? ReadColmapModel(spec.path)
                              : spec.format == "colmap-text"
                                  ? ReadColmapText(spec.path)
                                  : ReadColmapBinary(spec.path);
    return RigFromColmap(model, spec.path);
  }
  if (Contains(DatasetRigFormats(), spec.format)) {
    return ReadDatasetRig(spec.format, spec.path, info);
  }
  throw InputError(spec.path, "FORMAT", "one of " + Join(ReadableRigFormats()),
                   "'" + spec.format + "'");
}

void WriteRig(const Rig& rig, const RigSpec& spec, const RigFileInfo& info) {
  namespace fs = std::filesystem;
  if (!Contains(WritableRigFormats(), spec.format)) {
    throw InputError(spec.path, "FORMAT",
                     "a writable format: " + Join(WritableRigFormats()),
                     "'" + spec.format + "' (read-only)");
  }
  if (spec.format == "json") {
    const fs::path parent = fs::path(spec.path).parent_path();
    if (!parent.empty()) fs::create_directories(parent);
    WriteRigJson(rig, spec.path, info);
    return;
  }
  fs::create_directories(spec.path);
  WriteColmapModel(
      ColmapFromRig(rig), spec.path,
      spec.format == "colmap-text" ? ColmapFormat::kText : ColmapFormat::kBinary);
}

}  // namespace handlabel
