#include "capture/capture_import.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <climits>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <set>

#include "calib/colmap_model.h"
#include "calib/colmap_rig.h"
#include "calib/rig_json.h"
#include "capture/capture_format.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/version.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr char kImagePattern[] = "images/{camera}/{frame}.png";
constexpr char kImagesFolder[] = "images";

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

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool HasExtension(const fs::path& path, const std::vector<std::string>& extensions) {
  const std::string ext = Lower(path.extension().string());
  return std::find(extensions.begin(), extensions.end(), ext) != extensions.end();
}

std::string Join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : separator) + s;
  return out;
}

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string ManifestPath(const std::string& dir) {
  return (fs::path(dir) / kCaptureManifestFile).string();
}

CaptureManifest ReadManifestFile(const std::string& dir) {
  const std::string path = ManifestPath(dir);
  std::ifstream in(path);
  if (!in) {
    throw InputError(
        path, "file",
        "a capture manifest (make the capture with `handlabel capture init`)", "missing");
  }
  try {
    return ManifestFromJson(json::parse(in), path);
  } catch (const json::exception& e) {
    throw InputError(path, "content", "valid JSON", e.what());
  }
}

// Atomic: a reader sees the previous frame list or the new one.
void WriteManifest(const std::string& dir, const CaptureManifest& manifest) {
  WriteFileAtomically(ManifestPath(dir), ManifestToJson(manifest).dump(2) + "\n");
}

// Camera names become folder names.
void CheckCameraNames(const Rig& rig, const std::string& source) {
  for (const RigCamera& cam : rig.cameras()) {
    if (cam.name.empty() || cam.name == "." || cam.name == ".." ||
        cam.name.find_first_of("/\\") != std::string::npos) {
      throw InputError(source, "camera name",
                       "a name usable as a folder name (no '/', not '.' or '..')",
                       "\"" + cam.name + "\"");
    }
  }
}

}  // namespace

void CaptureInitOptions::Check() const {
  if (hand_side != "right" && hand_side != "left") {
    throw InputError("capture init options", "hand_side", "right or left", hand_side);
  }
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
  options.Check();
  if (rig.empty()) {
    throw InputError(options.rig_source, "cameras", "at least one camera", "none");
  }
  CheckCameraNames(rig, options.rig_source);
  const fs::path root(out_dir);
  if (fs::exists(root) && !fs::is_directory(root)) {
    throw InputError(out_dir, "--out", "a folder (or a path to create)",
                     "an existing file");
  }
  if (fs::exists(root / kCaptureManifestFile)) {
    if (!options.overwrite) {
      throw InputError(out_dir, "--out", "a folder without a capture (or --overwrite)",
                       "it already holds " + std::string(kCaptureManifestFile));
    }
    // The manifest goes first: a half-replaced folder is never a readable capture.
    fs::remove(root / kCaptureManifestFile);
    fs::remove_all(root / kImagesFolder);
  }
  CaptureManifest manifest;
  manifest.colmap_dir = "colmap";
  manifest.world = options.world.empty() ? rig_info.world : options.world;
  if (manifest.world.empty()) manifest.world = "as in " + options.rig_source;
  manifest.hand_side = options.hand_side;
  for (const RigCamera& cam : rig.cameras()) manifest.cameras.push_back(cam.name);
  manifest.files[kFileImage] = kImagePattern;
  manifest.generator = {{"tool", "handlabel capture init"},
                        {"handlabel_version", HandlabelVersion()},
                        {"rig", options.rig_source}};
  fs::create_directories(root / manifest.colmap_dir);
  RigFileInfo info;
  info.world = manifest.world;
  WriteRigJson(rig, (root / manifest.rig_file).string(), info);
  WriteColmapText(ColmapFromRig(rig), (root / manifest.colmap_dir).string());
  WriteManifest(out_dir, manifest);
}

std::string CaptureImportOptions::Matching() const {
  if (!match.empty()) return match;
  return videos_dir.empty() ? "name" : "index";
}

void CaptureImportOptions::Check() const {
  const char* source = "capture import options";
  if (images_dir.empty() == videos_dir.empty()) {
    throw InputError(source, "--images / --videos", "exactly one of them",
                     images_dir.empty() ? "neither" : "both");
  }
  if (Matching() != "name" && Matching() != "index") {
    throw InputError(source, "--match", "name or index", match);
  }
  if (!videos_dir.empty() && Matching() != "index") {
    throw InputError(source, "--match", "index for videos (frames have no names)", match);
  }
  if (!offsets.empty() && Matching() != "index") {
    throw InputError(source, "--offset", "--match index (offsets shift frame indices)",
                     "--match " + Matching());
  }
  if (start < 0) throw InputError(source, "--start", ">= 0", std::to_string(start));
  if (end != -1 && end <= start) {
    throw InputError(source, "--end", "-1 (to the end) or > --start",
                     std::to_string(end));
  }
  if (stride < 1) throw InputError(source, "--stride", ">= 1", std::to_string(stride));
  if (max_frames < 0) {
    throw InputError(source, "--max-frames", ">= 0 (0 = all)",
                     std::to_string(max_frames));
  }
  if (resume && overwrite) {
    throw InputError(source, "--resume / --overwrite", "at most one of them", "both");
  }
  if (checkpoint_frames < 1) {
    throw InputError(source, "checkpoint_frames", ">= 1",
                     std::to_string(checkpoint_frames));
  }
  if (num_threads < 0) {
    throw InputError(source, "--threads", ">= 0 (0 = all cores)",
                     std::to_string(num_threads));
  }
}

namespace {

// One rig camera's recording: an image folder or a video file.
struct CameraSource {
  std::string camera;
  fs::path path;
  std::vector<fs::path> images;  // image folders: the images, sorted by name
};

// One frame to import: its id and, per camera (rig order), the position of its image
// in the camera's folder or its video frame index.
struct PlannedFrame {
  std::string id;
  std::vector<int> index;
};

// Name -> path of every source in `dir`: camera sub-folders, or video files by stem.
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

// Assigns a source to every rig camera: --map first, then sources named after a
// camera. Sources left over are reported in a note.
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
  std::vector<std::string> found;
  for (const auto& [source, path] : sources) found.push_back(path.filename().string());
  std::vector<CameraSource> out;
  for (const std::string& camera : camera_names) {
    if (!camera_to_source.count(camera)) {
      throw InputError(dir.string(), "camera " + camera,
                       std::string(videos ? "a video " + camera + ".<mp4|mkv|avi|...>"
                                          : "a folder " + camera + "/ of images") +
                           " (or --map SOURCE=" + camera + ")",
                       found.empty() ? "nothing there" : "only " + Join(found, ", "));
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

// Frames are the file stems every camera folder has, in sorted order.
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

// Timeline frame t is camera c's own frame t + offset[c]; frames are the timeline
// positions every camera has.
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

ImageU8 RgbFromBgr(const cv::Mat& bgr) {
  HL_CHECK(bgr.type() == CV_8UC3, "expected an 8-bit 3-channel image");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  ImageU8 out(rgb.cols, rgb.rows, 3);
  for (int y = 0; y < rgb.rows; ++y) {
    std::copy(rgb.ptr<uint8_t>(y), rgb.ptr<uint8_t>(y) + 3 * rgb.cols,
              out.data.begin() + out.index(0, y));
  }
  return out;
}

// A video ended before the frame asked for (containers may declare more frames than
// they hold): the import stops there.
struct VideoEnded : std::exception {
  VideoEnded(int c, int n) : camera(c), frames_read(n) {}
  const char* what() const noexcept override { return "video ended"; }
  int camera;
  int frames_read;
};

// Reads frame `index` of camera `camera` as RGB; Where() names it in messages.
class FrameReader {
 public:
  virtual ~FrameReader() = default;
  virtual ImageU8 Read(int camera, int index) = 0;
  virtual std::string Where(int camera, int index) const = 0;
};

class ImageFolderReader : public FrameReader {
 public:
  explicit ImageFolderReader(const std::vector<CameraSource>& cameras)
      : cameras_(cameras) {}
  ImageU8 Read(int camera, int index) override {
    const std::string path = Where(camera, index);
    // 8-bit BGR whatever the file holds (gray is replicated, 16 bits are scaled down).
    const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) {
      throw InputError(path, "image",
                       "an image file OpenCV can decode (PNG, JPEG, BMP, TIFF)",
                       "unreadable");
    }
    return RgbFromBgr(bgr);
  }
  std::string Where(int camera, int index) const override {
    return cameras_[camera].images[index].string();
  }

 private:
  const std::vector<CameraSource>& cameras_;
};

// Decodes each video forward only (grab() up to the wanted frame): exact for every
// codec, unlike seeking.
class VideoReader : public FrameReader {
 public:
  explicit VideoReader(const std::vector<CameraSource>& cameras) : cameras_(cameras) {
    for (const CameraSource& source : cameras) {
      auto stream = std::make_unique<Stream>();
      const std::string path = source.path.string();
      if (!stream->capture.open(path, cv::CAP_FFMPEG)) {
        throw InputError(
            path, "video",
            "a video OpenCV's FFmpeg backend can open (camera " + source.camera + ")",
            "cannot open it");
      }
      streams_.push_back(std::move(stream));
    }
  }
  // Frame count the container declares; -1 if it declares none.
  int DeclaredCount(int camera) const {
    const double n = streams_[camera]->capture.get(cv::CAP_PROP_FRAME_COUNT);
    return n >= 1 ? static_cast<int>(n) : -1;
  }
  // Size the stream declares.
  std::pair<int, int> DeclaredSize(int camera) const {
    const cv::VideoCapture& c = streams_[camera]->capture;
    return {static_cast<int>(c.get(cv::CAP_PROP_FRAME_WIDTH)),
            static_cast<int>(c.get(cv::CAP_PROP_FRAME_HEIGHT))};
  }
  // Counts by decoding on a second handle (for containers that declare no count).
  int CountByDecoding(int camera) const {
    cv::VideoCapture counter(cameras_[camera].path.string(), cv::CAP_FFMPEG);
    int n = 0;
    while (counter.grab()) ++n;
    return n;
  }
  ImageU8 Read(int camera, int index) override {
    Stream& s = *streams_[camera];
    HL_CHECK(index >= s.next, "video frames are read in increasing order");
    while (s.next < index) {
      if (!s.capture.grab()) throw VideoEnded{camera, s.next};
      ++s.next;
    }
    cv::Mat frame;
    if (!s.capture.read(frame) || frame.empty()) throw VideoEnded{camera, s.next};
    ++s.next;
    if (frame.type() == CV_8UC1) cv::cvtColor(frame, frame, cv::COLOR_GRAY2BGR);
    if (frame.type() == CV_8UC4) cv::cvtColor(frame, frame, cv::COLOR_BGRA2BGR);
    if (frame.type() != CV_8UC3) {
      throw InputError(Where(camera, index), "pixels", "8-bit colour or gray frames",
                       "OpenCV type " + std::to_string(frame.type()));
    }
    return RgbFromBgr(frame);
  }
  std::string Where(int camera, int index) const override {
    return cameras_[camera].path.string() + " frame " + std::to_string(index);
  }

 private:
  struct Stream {
    cv::VideoCapture capture;
    int next = 0;  // index of the frame the next read() returns
  };
  const std::vector<CameraSource>& cameras_;
  std::vector<std::unique_ptr<Stream>> streams_;
};

void CheckSize(int width, int height, const RigCamera& cam, const std::string& where) {
  if (width != cam.camera.width() || height != cam.camera.height()) {
    throw InputError(where, "size",
                     SizeText(cam.camera.width(), cam.camera.height()) + " (camera " +
                         cam.name + " in the rig)",
                     SizeText(width, height));
  }
}

// The message of the exception being handled.
std::string CurrentErrorText() {
  try {
    throw;
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "an exception that is not a std::exception";
  }
}

// What resume compares: everything that decides which pixels become which frame.
json ImportSettings(const CaptureImportOptions& o) {
  const bool videos = !o.videos_dir.empty();
  const std::string dir = videos ? o.videos_dir : o.images_dir;
  return {{"source", videos ? "videos" : "images"},
          {"dir", fs::absolute(dir).lexically_normal().string()},
          {"match", o.Matching()},
          {"map", o.source_to_camera},
          {"offsets", o.offsets},
          {"start", o.start},
          {"end", o.end},
          {"stride", o.stride},
          {"max_frames", o.max_frames}};
}

// The rig file's cameras in the manifest's order.
Rig ReadManifestRig(const std::string& dir, const CaptureManifest& manifest) {
  const Rig file_rig = ReadRigJson((fs::path(dir) / manifest.rig_file).string());
  Rig rig;
  for (const std::string& name : manifest.cameras) {
    if (file_rig.IndexOf(name) < 0) {
      throw InputError(ManifestPath(dir), "cameras",
                       "camera names that " + manifest.rig_file + " defines", name);
    }
    rig.Add(file_rig.Find(name));
  }
  return rig;
}

// Applies resume / overwrite to a manifest that already lists frames.
void PrepareFrames(const std::string& dir, const CaptureImportOptions& o,
                   const json& settings, CaptureManifest* manifest) {
  const std::string path = ManifestPath(dir);
  if (manifest->frames.empty()) return;
  if (o.overwrite) {
    manifest->frames.clear();
    WriteManifest(dir, *manifest);  // first: no listed frame loses its images
    fs::remove_all(fs::path(dir) / kImagesFolder);
    return;
  }
  const std::string count = std::to_string(manifest->frames.size()) + " frames";
  if (!o.resume) {
    throw InputError(path, "frames",
                     "none (--resume continues an interrupted import with the same "
                     "settings, --overwrite imports again)",
                     count);
  }
  const json previous = manifest->generator.value("import", json());
  if (previous != settings) {
    throw InputError(path, "generator.import",
                     "the settings of this import (--resume continues an import with "
                     "the same sources and options: " +
                         settings.dump() + ")",
                     previous.dump());
  }
}

}  // namespace

CaptureImportReport ImportCapture(const std::string& capture_dir,
                                  const CaptureImportOptions& o,
                                  const CaptureImportCallbacks& callbacks) {
  const auto start_time = std::chrono::steady_clock::now();
  o.Check();
  CaptureImportReport report;
  auto note = [&](const std::string& text) {
    report.notes.push_back(text);
    if (callbacks.note) callbacks.note(text);
  };
  CaptureManifest manifest = ReadManifestFile(capture_dir);
  if (!manifest.files.count(kFileImage) ||
      manifest.files.at(kFileImage) != kImagePattern) {
    throw InputError(
        ManifestPath(capture_dir), "files.image",
        std::string(kImagePattern) + " (a capture made by `capture init`)",
        manifest.files.count(kFileImage) ? manifest.files.at(kFileImage) : "missing");
  }
  const Rig rig = ReadManifestRig(capture_dir, manifest);
  const json settings = ImportSettings(o);
  PrepareFrames(capture_dir, o, settings, &manifest);

  const bool videos = !o.videos_dir.empty();
  const fs::path source_dir(videos ? o.videos_dir : o.images_dir);
  std::vector<std::string> notes;
  std::vector<CameraSource> cameras =
      MatchSources(ListSources(source_dir, videos, videos ? "--videos" : "--images"), rig,
                   o, source_dir, videos, &notes);
  std::unique_ptr<FrameReader> reader;
  std::vector<int> counts;
  if (videos) {
    auto video = std::make_unique<VideoReader>(cameras);
    for (size_t c = 0; c < cameras.size(); ++c) {
      const auto [width, height] = video->DeclaredSize(c);
      CheckSize(width, height, rig[c], cameras[c].path.string());
      int count = video->DeclaredCount(c);
      if (count < 0) {
        count = video->CountByDecoding(c);
        notes.push_back(cameras[c].path.filename().string() +
                        " declares no frame count: counted " + std::to_string(count) +
                        " by decoding");
      }
      counts.push_back(count);
    }
    reader = std::move(video);
  } else {
    for (CameraSource& source : cameras) {
      ListImages(&source);
      counts.push_back(static_cast<int>(source.images.size()));
    }
    reader = std::make_unique<ImageFolderReader>(cameras);
  }
  const std::vector<PlannedFrame> plan = o.Matching() == "name"
                                             ? PlanByName(cameras, o, &notes)
                                             : PlanByIndex(cameras, counts, o, &notes);
  for (const std::string& text : notes) note(text);
  if (plan.empty()) {
    throw InputError(videos ? "--videos" : "--images", "frames",
                     "at least one frame in the range (--start, --end, --stride)",
                     "none");
  }
  report.frames_total = static_cast<int>(plan.size());
  report.frames_kept = static_cast<int>(manifest.frames.size());
  for (int k = 0; k < report.frames_kept; ++k) {
    if (k >= report.frames_total || plan[k].id != manifest.frames[k]) {
      throw InputError(ManifestPath(capture_dir), "frames[" + std::to_string(k) + "]",
                       k < report.frames_total ? plan[k].id : "no frame (past the plan)",
                       manifest.frames[k] +
                           " (the sources changed since the import "
                           "began? --overwrite imports again)");
    }
  }

  for (const std::string& camera : manifest.cameras) {
    const fs::path folder = fs::path(capture_dir) / kImagesFolder / camera;
    fs::create_directories(folder);
    RemoveStaleTemporaries(folder.string());
  }
  manifest.generator["tool"] = "handlabel capture import";
  manifest.generator["handlabel_version"] = HandlabelVersion();
  manifest.generator["import"] = settings;
  manifest.generator["import_status"] = "running";
  manifest.generator["import_notes"] = report.notes;
  WriteManifest(capture_dir, manifest);

  tbb::task_arena arena(o.num_threads > 0 ? o.num_threads : tbb::task_arena::automatic);
  int since_checkpoint = 0;
  if (callbacks.progress) callbacks.progress(report.frames_kept, report.frames_total);
  try {
    for (int k = report.frames_kept; k < report.frames_total; ++k) {
      const PlannedFrame& frame = plan[k];
      arena.execute([&] {
        tbb::parallel_for(0, static_cast<int>(rig.size()), [&](int c) {
          const ImageU8 rgb = reader->Read(c, frame.index[c]);
          CheckSize(rgb.width, rgb.height, rig[c], reader->Where(c, frame.index[c]));
          const std::string path = (fs::path(capture_dir) /
                                    ExpandPattern(kImagePattern, rig[c].name, frame.id))
                                       .string();
          WriteFileAtomically(path, EncodePng(rgb, o.png));
        });
      });
      manifest.frames.push_back(frame.id);
      ++report.frames_written;
      if (++since_checkpoint >= o.checkpoint_frames) {
        WriteManifest(capture_dir, manifest);
        since_checkpoint = 0;
      }
      if (callbacks.progress) callbacks.progress(k + 1, report.frames_total);
    }
    manifest.generator["import_status"] = "complete";
  } catch (const VideoEnded& ended) {
    report.stopped_early = true;
    const int k = report.frames_kept + report.frames_written;
    note(cameras[ended.camera].path.filename().string() + " ended after " +
         std::to_string(ended.frames_read) + " frames (it declares " +
         std::to_string(counts[ended.camera]) + "): the import stopped before frame " +
         plan[k].id + "; " + std::to_string(k) + " frames are in the capture");
    manifest.generator["import_status"] = "complete (a video ended early)";
  } catch (...) {
    // Keep every frame written so far; --resume continues after them.
    manifest.generator["import_status"] = "failed: " + CurrentErrorText();
    WriteManifest(capture_dir, manifest);
    throw;
  }
  manifest.generator["import_notes"] = report.notes;
  WriteManifest(capture_dir, manifest);
  report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time)
          .count();
  return report;
}

}  // namespace handlabel
