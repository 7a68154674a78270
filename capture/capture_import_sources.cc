#include "capture/capture_import_sources.h"

#include <algorithm>
#include <climits>

#include "capture/capture_format.h"
#include "core/errors.h"
#include "core/text.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string>& ImageExtensions() {
  static const std::vector<std::string> e = {".png", ".jpg", ".jpeg",
                                             ".bmp", ".tif", ".tiff"};
  return e;
}

const std::vector<std::string>& VideoExtensions() {
  static const std::vector<std::string> e = {".mp4", ".mkv", ".avi",  ".mov", ".webm",
                                             ".m4v", ".mpg", ".mpeg", ".ts",  ".wmv"};
  return e;
}

bool HasExtension(const fs::path& path, const std::vector<std::string>& extensions) {
  const std::string ext = Lower(path.extension().string());
  return std::find(extensions.begin(), extensions.end(), ext) != extensions.end();
}

// Positions first, first + stride, ... below `end`, at most max_frames of them.
std::vector<int> SelectPositions(int first, int end, const CaptureImportOptions& o) {
  std::vector<int> out;
  for (int t = first; t < end; t += o.stride) {
    if (o.max_frames > 0 && static_cast<int>(out.size()) >= o.max_frames) break;
    out.push_back(t);
  }
  return out;
}

int EffectiveEnd(int available, const CaptureImportOptions& o) {
  return o.end < 0 ? available : std::min(available, o.end);
}

}  // namespace

std::map<std::string, fs::path> ListSources(const fs::path& dir, bool videos,
                                            const std::string& flag) {
  if (!fs::is_directory(dir)) {
    throw InputError(flag, "value", "an existing folder", dir.string());
  }
  std::map<std::string, fs::path> sources;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    if (!videos) {
      if (entry.is_directory()) sources[name] = entry.path();
      continue;
    }
    if (!entry.is_regular_file() || !HasExtension(entry.path(), VideoExtensions())) {
      continue;
    }
    const std::string stem = entry.path().stem().string();
    if (sources.count(stem)) {
      throw InputError(dir.string(), "video " + stem, "one video per camera",
                       sources[stem].filename().string() + " and " + name);
    }
    sources[stem] = entry.path();
  }
  return sources;
}

std::vector<CameraSource> MatchSources(const std::map<std::string, fs::path>& sources,
                                       const Rig& rig, const CaptureImportOptions& o,
                                       const fs::path& dir, bool videos,
                                       std::vector<std::string>* notes) {
  std::vector<std::string> camera_names;
  for (const RigCamera& cam : rig.cameras()) camera_names.push_back(cam.name);
  std::map<std::string, std::string> camera_to_source;
  for (const auto& [source, camera] : o.source_to_camera) {
    const std::string entry = source + "=" + camera;
    if (!sources.count(source)) {
      throw InputError("--map", entry,
                       std::string(videos ? "a video" : "a folder") + " named " + source +
                           " in " + dir.string(),
                       "none");
    }
    if (rig.IndexOf(camera) < 0) {
      throw InputError("--map", entry,
                       "a camera of the rig (" + Join(camera_names, ", ") + ")", camera);
    }
    if (camera_to_source.count(camera)) {
      throw InputError("--map", camera, "one source per camera",
                       camera_to_source[camera] + " and " + source);
    }
    camera_to_source[camera] = source;
  }
  std::vector<std::string> ignored;
  for (const auto& [source, path] : sources) {
    if (o.source_to_camera.count(source)) continue;
    if (rig.IndexOf(source) >= 0 && !camera_to_source.count(source)) {
      camera_to_source[source] = source;
    } else {
      ignored.push_back(path.filename().string());
    }
  }
  // What each source went to: a camera without one is named with where its namesake
  // went (`--map cam01=cam00` leaves cam01 without a source while cam01/ is there).
  std::map<std::string, std::string> source_to_camera;
  for (const auto& [camera, source] : camera_to_source) source_to_camera[source] = camera;
  std::vector<std::string> found;
  for (const auto& [source, path] : sources) {
    const auto to = source_to_camera.find(source);
    found.push_back(path.filename().string() +
                    (to == source_to_camera.end() ? " (unused)"
                     : o.source_to_camera.count(source)
                         ? " (--map " + source + "=" + to->second + ")"
                         : " (camera " + to->second + ")"));
  }
  std::vector<CameraSource> out;
  for (const std::string& camera : camera_names) {
    if (!camera_to_source.count(camera)) {
      throw InputError(dir.string(), "camera " + camera,
                       std::string(videos ? "a video " + camera + ".<mp4|mkv|avi|...>"
                                          : "a folder " + camera + "/ of images") +
                           " (or --map SOURCE=" + camera + ")",
                       found.empty() ? "nothing there" : Join(found, ", "));
    }
    out.push_back({camera, sources.at(camera_to_source[camera]), {}});
  }
  if (!ignored.empty()) {
    notes->push_back("ignored in " + dir.string() +
                     " (no rig camera of that name; --map SOURCE=CAMERA assigns one): " +
                     Join(ignored, ", "));
  }
  return out;
}

void ListImages(CameraSource* source) {
  for (const auto& entry : fs::directory_iterator(source->path)) {
    const std::string name = entry.path().filename().string();
    if (!name.empty() && name[0] != '.' && entry.is_regular_file() &&
        HasExtension(entry.path(), ImageExtensions())) {
      source->images.push_back(entry.path());
    }
  }
  std::sort(source->images.begin(), source->images.end());
  if (source->images.empty()) {
    throw InputError(source->path.string(), "images",
                     "at least one image (" + Join(ImageExtensions(), " ") + ")", "none");
  }
}

std::vector<PlannedFrame> PlanByName(const std::vector<CameraSource>& cameras,
                                     const CaptureImportOptions& o,
                                     std::vector<std::string>* notes) {
  std::vector<std::map<std::string, int>> position_of(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    const auto& images = cameras[c].images;
    for (size_t i = 0; i < images.size(); ++i) {
      const std::string stem = images[i].stem().string();
      const auto [it, added] = position_of[c].emplace(stem, static_cast<int>(i));
      if (!added) {
        throw InputError(cameras[c].path.string(), "image " + stem,
                         "one file per frame name (or --match index)",
                         images[it->second].filename().string() + " and " +
                             images[i].filename().string());
      }
    }
  }
  std::vector<std::string> common;
  for (const auto& [stem, position] : position_of[0]) {
    bool everywhere = true;
    for (const auto& names : position_of) everywhere = everywhere && names.count(stem);
    if (everywhere) common.push_back(stem);
  }
  if (common.empty()) {
    throw InputError(o.images_dir, "frames",
                     "file names (without extension) that every camera folder has (or "
                     "--match index)",
                     "none in common");
  }
  std::vector<std::string> per_camera;
  bool all_common = true;
  for (const CameraSource& source : cameras) {
    per_camera.push_back(source.camera + " " + std::to_string(source.images.size()));
    all_common = all_common && source.images.size() == common.size();
  }
  if (!all_common) {
    notes->push_back("images per camera: " + Join(per_camera, ", ") + ". " +
                     std::to_string(common.size()) +
                     " frame names are in every camera folder; the others are left out.");
  }
  std::vector<PlannedFrame> plan;
  const int n = static_cast<int>(common.size());
  for (int p : SelectPositions(o.start, EffectiveEnd(n, o), o)) {
    PlannedFrame frame{common[p], {}};
    for (const auto& names : position_of) frame.index.push_back(names.at(common[p]));
    plan.push_back(frame);
  }
  return plan;
}

std::vector<PlannedFrame> PlanByIndex(const std::vector<CameraSource>& cameras,
                                      const std::vector<int>& counts,
                                      const CaptureImportOptions& o,
                                      std::vector<std::string>* notes) {
  std::vector<int> offset(cameras.size(), 0);
  for (const auto& [camera, value] : o.offsets) {
    bool known = false;
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (cameras[c].camera == camera) {
        offset[c] = value;
        known = true;
      }
    }
    if (!known) {
      throw InputError("--offset", camera + "=" + std::to_string(value),
                       "a camera of the rig", camera);
    }
  }
  int first = 0, available = INT_MAX;
  bool counts_differ = false, any_offset = false;
  std::vector<std::string> per_camera;
  for (size_t c = 0; c < cameras.size(); ++c) {
    first = std::max(first, -offset[c]);
    available = std::min(available, counts[c] - offset[c]);
    counts_differ = counts_differ || counts[c] != counts[0];
    any_offset = any_offset || offset[c] != 0;
    per_camera.push_back(
        cameras[c].camera + " " + std::to_string(counts[c]) +
        (offset[c] ? " (offset " + std::to_string(offset[c]) + ")" : ""));
  }
  if (available <= first) {
    throw InputError(o.offsets.empty() ? "frames" : "--offset", "frames",
                     "timeline frames that every camera has (frames per camera: " +
                         Join(per_camera, ", ") + ")",
                     "none");
  }
  if (counts_differ || any_offset) {
    notes->push_back("frames per camera: " + Join(per_camera, ", ") +
                     ". Timeline frames " + std::to_string(first) + " to " +
                     std::to_string(available - 1) +
                     " are in every camera; frames outside them are left out.");
  }
  std::vector<PlannedFrame> plan;
  for (int t : SelectPositions(std::max(first, o.start), EffectiveEnd(available, o), o)) {
    PlannedFrame frame{FrameId(t), {}};
    for (size_t c = 0; c < cameras.size(); ++c) frame.index.push_back(t + offset[c]);
    plan.push_back(frame);
  }
  return plan;
}

}  // namespace handlabel
