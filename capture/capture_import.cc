#include "capture/capture_import.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cameras/rig_json.h"
#include "capture/capture_import_sources.h"
#include "capture/capture_manifest_file.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/file_lock.h"
#include "core/option_checks.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "core/version.h"
#include "media/frame_readers.h"

namespace handlabel {

std::string CaptureImportOptions::Matching() const {
  if (!match.empty()) return match;
  return videos_dir.empty() ? "name" : "index";
}

void CaptureImportOptions::Check(const std::string& source) const {
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
  RequireAtLeast(source, "--start", start, 0);
  if (end != -1 && end <= start) {
    throw InputError(source, "--end", "-1 (to the end) or > --start",
                     std::to_string(end));
  }
  RequireAtLeast(source, "--stride", stride, 1);
  RequireAtLeast(source, "--max-frames", max_frames, 0, ">= 0 (0 = all)");
  if (resume && overwrite) {
    throw InputError(source, "--resume / --overwrite", "at most one of them", "both");
  }
  RequireAtLeast(source, "checkpoint_frames", checkpoint_frames, 1);
  RequireAtLeast(source, "--threads", num_threads, 0, ">= 0 (0 = all cores)");
}

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

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
      throw InputError(CaptureManifestPath(dir), "cameras",
                       "camera names that " + manifest.rig_file + " defines", name);
    }
    rig.Add(file_rig.Find(name));
  }
  return rig;
}

// Removes from the manifest every kind of file but the images (detections, keypoints,
// masks, ground truth, ...): what was made from or for the images an --overwrite
// import replaces. Returns them as "kind (pattern)".
std::vector<std::string> UnlistDerivedFiles(CaptureManifest* manifest) {
  std::vector<std::string> dropped;
  for (auto it = manifest->files.begin(); it != manifest->files.end();) {
    if (it->first == kFileImage) {
      ++it;
      continue;
    }
    dropped.push_back(it->first + " (" + it->second + ")");
    it = manifest->files.erase(it);
  }
  return dropped;
}

// Applies resume / overwrite to a manifest that already lists frames (or, with
// overwrite, other files than images); what was dropped goes to `notes`.
void PrepareFrames(const std::string& dir, const CaptureImportOptions& o,
                   const json& settings, CaptureManifest* manifest,
                   std::vector<std::string>* notes) {
  const std::string path = CaptureManifestPath(dir);
  if (o.overwrite) {
    const std::vector<std::string> dropped = UnlistDerivedFiles(manifest);
    if (!dropped.empty()) {
      notes->push_back("--overwrite: capture.json no longer lists " + Join(dropped, ", ") +
                       ": they describe the images being replaced (their files stay on "
                       "disk; `handlabel detect --capture` makes detections of the new "
                       "images)");
    }
    if (manifest->frames.empty() && dropped.empty()) return;
    manifest->frames.clear();
    WriteCaptureManifest(dir, *manifest);  // first: no listed frame loses its images
    fs::remove_all(fs::path(dir) / kImportImagesFolder);
    return;
  }
  if (manifest->frames.empty()) return;
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

// The rig cameras' recordings: matched sources, a reader, and frames per camera.
struct OpenedSources {
  std::vector<CameraSource> cameras;
  std::unique_ptr<FrameReader> reader;
  std::vector<int> counts;
};

// Index matching pairs frame t of every video: that is one moment only when the videos
// run at one rate. Rates are compared with the first camera's (0.1 %: 29.97 vs 30 is
// a difference, container rounding such as 30 vs 30.0003 is not).
void CheckFrameRates(const VideoReader& video, const std::vector<CameraSource>& cameras,
                     bool allow_mixed, std::vector<std::string>* notes) {
  const double first = video.DeclaredFps(0);
  for (size_t c = 1; c < cameras.size(); ++c) {
    const double fps = video.DeclaredFps(c);
    if (first <= 0 || fps <= 0 || std::abs(fps - first) <= 1e-3 * first) continue;
    const std::string both = cameras[c].path.filename().string() + " (camera " +
                             cameras[c].camera + ") runs at " + FormatNumber(fps) +
                             " fps, " + cameras[0].path.filename().string() +
                             " (camera " + cameras[0].camera + ") at " +
                             FormatNumber(first) + " fps";
    if (!allow_mixed) {
      throw InputError("--videos", "frame rate",
                       "videos of one frame rate (frames are paired by index; "
                       "--allow-mixed-fps pairs them all the same)",
                       both);
    }
    notes->push_back(both + ": paired by index all the same (--allow-mixed-fps)");
  }
}

OpenedSources OpenSources(const Rig& rig, const CaptureImportOptions& o,
                          std::vector<std::string>* notes) {
  const bool videos = !o.videos_dir.empty();
  const fs::path dir(videos ? o.videos_dir : o.images_dir);
  OpenedSources s;
  s.cameras = MatchSources(ListSources(dir, videos, videos ? "--videos" : "--images"),
                           rig, o, dir, videos, notes);
  if (!videos) {
    for (CameraSource& source : s.cameras) {
      ListImages(&source);
      s.counts.push_back(static_cast<int>(source.images.size()));
    }
    s.reader = MakeImageFolderReader(s.cameras);
    return s;
  }
  auto video = std::make_unique<VideoReader>(s.cameras);
  for (size_t c = 0; c < s.cameras.size(); ++c) {
    const auto [width, height] = video->DeclaredSize(c);
    CheckSize(width, height, rig[c], s.cameras[c].path.string());
    int count = video->DeclaredCount(c);
    if (count < 0) {
      count = video->CountByDecoding(c);
      notes->push_back(s.cameras[c].path.filename().string() +
                       " declares no frame count: counted " + std::to_string(count) +
                       " by decoding");
    }
    s.counts.push_back(count);
  }
  CheckFrameRates(*video, s.cameras, o.allow_mixed_fps, notes);
  s.reader = std::move(video);
  return s;
}

// Frames already in capture.json (resume) must be the plan's first ones.
void CheckKeptFrames(const std::string& dir, const std::vector<PlannedFrame>& plan,
                     const CaptureManifest& manifest) {
  const size_t total = plan.size();
  for (size_t k = 0; k < manifest.frames.size(); ++k) {
    if (k >= total || plan[k].id != manifest.frames[k]) {
      throw InputError(CaptureManifestPath(dir), "frames[" + std::to_string(k) + "]",
                       k < total ? plan[k].id : "no frame (past the plan)",
                       manifest.frames[k] +
                           " (the sources changed since the import "
                           "began? --overwrite imports again)");
    }
  }
}

// Makes the camera folders and records in the manifest that an import is running.
void BeginImport(const std::string& dir, const json& settings,
                 const std::vector<std::string>& notes, CaptureManifest* manifest) {
  for (const std::string& camera : manifest->cameras) {
    const fs::path folder = fs::path(dir) / kImportImagesFolder / camera;
    fs::create_directories(folder);
    RemoveStaleTemporaries(folder.string());
  }
  manifest->generator["tool"] = "handlabel capture import";
  manifest->generator["handlabel_version"] = HandlabelVersion();
  manifest->generator["import"] = settings;
  manifest->generator["import_status"] = "running";
  manifest->generator["import_notes"] = notes;
  WriteCaptureManifest(dir, *manifest);
}

// Reads and writes one frame's image of every camera, the cameras in parallel.
void ImportFrame(const std::string& dir, const Rig& rig, const PlannedFrame& frame,
                 FrameReader* reader, const CaptureImportOptions& o,
                 tbb::task_arena* arena) {
  arena->execute([&] {
    tbb::parallel_for(0, static_cast<int>(rig.size()), [&](int c) {
      const ImageU8 rgb = reader->Read(c, frame.index[c]);
      CheckSize(rgb.width, rgb.height, rig[c], reader->Where(c, frame.index[c]));
      const std::string path =
          (fs::path(dir) / ExpandPattern(kImportImagePattern, rig[c].name, frame.id))
              .string();
      WriteFileAtomically(path, EncodePng(rgb, o.png));
    });
  });
}

// The capture made by `capture init`, with its rig in the manifest's camera order.
CaptureManifest ReadInitializedCapture(const std::string& dir) {
  CaptureManifest manifest =
      ReadCaptureManifest(dir, "make the capture with `handlabel capture init`");
  if (!manifest.files.count(kFileImage) ||
      manifest.files.at(kFileImage) != kImportImagePattern) {
    throw InputError(
        CaptureManifestPath(dir), "files.image",
        std::string(kImportImagePattern) + " (a capture made by `capture init`)",
        manifest.files.count(kFileImage) ? manifest.files.at(kFileImage) : "missing");
  }
  return manifest;
}

}  // namespace

CaptureImportReport ImportCapture(const std::string& capture_dir,
                                  const CaptureImportOptions& o,
                                  const CaptureImportCallbacks& callbacks) {
  const auto start_time = std::chrono::steady_clock::now();
  o.Check("capture import options");
  CaptureImportReport report;
  auto note = [&](const std::string& text) {
    report.notes.push_back(text);
    if (callbacks.note) callbacks.note(text);
  };
  ReadInitializedCapture(capture_dir);  // a missing capture is named before any lock
  const FileLock writer =
      LockFolderForWriting(capture_dir, "capture import", "--capture", "");
  // Read again under the lock: as the last writer left it.
  CaptureManifest manifest = ReadInitializedCapture(capture_dir);
  const Rig rig = ReadManifestRig(capture_dir, manifest);
  const json settings = ImportSettings(o);
  std::vector<std::string> notes;
  OpenedSources sources = OpenSources(rig, o, &notes);
  const std::vector<PlannedFrame> plan =
      o.Matching() == "name" ? PlanByName(sources.cameras, o, &notes)
                             : PlanByIndex(sources.cameras, sources.counts, o, &notes);
  for (const std::string& text : notes) note(text);
  if (plan.empty()) {
    throw InputError(o.videos_dir.empty() ? "--images" : "--videos", "frames",
                     "at least one frame in the range (--start, --end, --stride)",
                     "none");
  }
  // Only with sources that give frames does --overwrite drop what the capture held.
  notes.clear();
  PrepareFrames(capture_dir, o, settings, &manifest, &notes);
  for (const std::string& text : notes) note(text);
  CheckKeptFrames(capture_dir, plan, manifest);
  report.frames_total = static_cast<int>(plan.size());
  report.frames_kept = static_cast<int>(manifest.frames.size());
  BeginImport(capture_dir, settings, report.notes, &manifest);

  tbb::task_arena arena(o.num_threads > 0 ? o.num_threads : tbb::task_arena::automatic);
  int since_checkpoint = 0;
  if (callbacks.progress) callbacks.progress(report.frames_kept, report.frames_total);
  try {
    for (int k = report.frames_kept; k < report.frames_total; ++k) {
      ImportFrame(capture_dir, rig, plan[k], sources.reader.get(), o, &arena);
      manifest.frames.push_back(plan[k].id);
      ++report.frames_written;
      if (++since_checkpoint >= o.checkpoint_frames) {
        WriteCaptureManifest(capture_dir, manifest);
        since_checkpoint = 0;
      }
      if (callbacks.progress) callbacks.progress(k + 1, report.frames_total);
    }
    manifest.generator["import_status"] = "complete";
  } catch (const VideoEnded& ended) {
    report.stopped_early = true;
    const int k = report.frames_kept + report.frames_written;
    note(sources.cameras[ended.camera].path.filename().string() + " ended after " +
         std::to_string(ended.frames_read) + " frames (it declares " +
         std::to_string(sources.counts[ended.camera]) +
         "): the import stopped before frame " + plan[k].id + "; " + std::to_string(k) +
         " frames are in the capture");
    manifest.generator["import_status"] = "complete (a video ended early)";
  } catch (...) {
    // Keep every frame written so far; --resume continues after them.
    manifest.generator["import_status"] = "failed: " + CurrentErrorText();
    WriteCaptureManifest(capture_dir, manifest);
    throw;
  }
  manifest.generator["import_notes"] = report.notes;
  WriteCaptureManifest(capture_dir, manifest);
  report.seconds = SecondsSince(start_time);
  return report;
}

}  // namespace handlabel
