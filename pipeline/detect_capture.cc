#include "pipeline/detect_capture.h"

#include <atomic>
#include <chrono>
#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "capture/capture_format.h"
#include "capture/capture_manifest_file.h"
#include "capture/capture_reader.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/file_lock.h"
#include "core/json_util.h"
#include "core/option_checks.h"
#include "core/stopwatch.h"
#include "core/worker_governor.h"
#include "image/image_file.h"
#include "network/detector/detector_overlay.h"

namespace handlabel {
namespace {

constexpr char kDetectionsPattern[] = "detections/{frame}.json";

// The capture's manifest with the detections kind listed (written atomically, last).
void ListDetections(const CaptureReader& capture) {
  CaptureManifest manifest = capture.manifest();
  manifest.files[kFileDetections] = kDetectionsPattern;
  WriteFileAtomically(capture.dir() + "/capture.json",
                      ManifestToJson(manifest).dump(2) + "\n");
}

// One picture per view: the image with the view's detection drawn on it.
void WriteDetectionOverlays(const std::string& dir, const std::string& frame,
                            const std::vector<std::string>& cameras,
                            const FrameHandResult& result, std::vector<ImageU8> images) {
  const std::filesystem::path frame_dir = std::filesystem::path(dir) / frame;
  std::filesystem::create_directories(frame_dir);
  for (size_t c = 0; c < cameras.size(); ++c) {
    DrawHandDetection(result.views[c], &images[c]);
    WriteFileAtomically((frame_dir / (cameras[c] + ".png")).string(),
                        EncodePng(images[c]));
  }
}

}  // namespace

void DetectCaptureOptions::Check(const std::string& source) const {
  hands.Check(source);
  multiview.Check(source);
  RequireAtLeast(source, "threads", threads, 0, ">= 0 (0 = one frame per core)");
  RequireAtLeast(source, "palm_every", palm_every, 0,
                 ">= 0 (0 = palm detection only where the track is lost)");
}

void DetectCaptureSummary::Add(const DetectCaptureSummary& other) {
  frames += other.frames;
  views += other.views;
  views_detected += other.views_detected;
  views_from_palm += other.views_from_palm;
  views_tracked += other.views_tracked;
  frames_tracked += other.frames_tracked;
  frames_with_hand += other.frames_with_hand;
  hands_found += other.hands_found;
  frames_with_hands += other.frames_with_hands;
  worker_parks += other.worker_parks;
}

std::vector<FrameRun> FrameRuns(int total, int palm_every) {
  std::vector<FrameRun> runs;
  for (int f = 0; f < total; ++f) {
    if (runs.empty() || (palm_every > 0 && f % palm_every == 0)) runs.push_back({f, f});
    runs.back().end = f + 1;
  }
  return runs;
}

namespace {

// One hand's record: "views" (native format plus the detector's per-view fields) and
// "hand" {found, side, side_score, palm_views}.
nlohmann::json HandDetectionsJson(const std::string& frame,
                                  const std::vector<std::string>& cameras,
                                  const FrameHandResult& result) {
  std::vector<ViewKeypoints> views(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    views[c].camera = cameras[c];
    views[c].keypoints = result.views[c].keypoints;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (views[c].keypoints.confidence(k) <= 0) {
        views[c].keypoints.uv_px.row(k).setConstant(
            std::numeric_limits<double>::quiet_NaN());
      }
    }
    views[c].visibility.fill(-1);
  }
  nlohmann::json out = ViewKeypointsToJson(frame, views, /*ground_truth=*/false);
  for (size_t c = 0; c < cameras.size(); ++c) {
    const ViewHandResult& r = result.views[c];
    nlohmann::json& jv = out["views"][c];
    jv["detected"] = r.detected;
    jv["palm_candidates"] = r.palm_candidates;
    if (r.detected) {
      jv["source"] = r.source;
      jv["presence"] = r.hand.presence;
      jv["handedness"] = {{"side", HandSideName(r.hand.side())},
                          {"score", r.hand.side_score()}};
      jv["median_reprojection_px"] = JsonNumberOrNull(r.median_reprojection_px);
    } else {
      jv["reason"] = r.reason;
      if (r.reason == "low_presence") jv["presence"] = r.hand.presence;
    }
    if (!r.region.empty()) jv["region"] = r.region;  // video mode only
  }
  out["hand"] = {{"found", result.found},
                 {"side", HandSideName(result.side)},
                 {"side_score", result.side_score},
                 {"palm_views", result.palm_views}};
  return out;
}

}  // namespace

nlohmann::json FrameDetectionsJson(const std::string& frame,
                                   const std::vector<std::string>& cameras,
                                   const FrameHandResult& result) {
  const nlohmann::json first = HandDetectionsJson(frame, cameras, result);
  nlohmann::json out = {{"frame", first["frame"]}, {"views", first["views"]}};
  out["detector"] = "mediapipe_hands";
  out["hand"] = first["hand"];
  if (!result.tracking.empty()) out["tracking"] = result.tracking;  // video mode only
  if (result.max_hands > 1) out["max_hands"] = result.max_hands;
  // Several hands (max_hands > 1): the first where a single-hand file has it, the
  // others after it, each with its views and hand record.
  for (const FrameHandResult& other : result.other_hands) {
    nlohmann::json hand = HandDetectionsJson(frame, cameras, other);
    hand.erase("frame");
    out["other_hands"].push_back(std::move(hand));
  }
  return out;
}

namespace {

// Detects one frame and writes its detections (and overlays); adds it to `summary`.
// Video mode: `previous` is the run's previous frame's result (nullptr on its first
// frame); per-frame mode: ignored. Returns the frame's result.
FrameHandResult DetectFrame(const CaptureReader& capture, int f,
                            const MediapipeHands& detector,
                            const DetectCaptureOptions& options,
                            const FrameHandResult* previous,
                            DetectCaptureSummary* summary) {
  const int n = capture.num_cameras();
  std::vector<ImageU8> images;
  for (int c = 0; c < n; ++c) images.push_back(capture.ReadImage(f, c));
  FrameHandResult result =
      options.video
          ? DetectHandInVideo(detector, capture.rig(), images, previous,
                              options.multiview)
          : DetectHandMultiView(detector, capture.rig(), images, options.multiview);
  const std::string id = capture.frame_id(f);
  if (!options.overlays_dir.empty()) {
    WriteDetectionOverlays(options.overlays_dir, id, capture.manifest().cameras, result,
                           std::move(images));
  }
  WriteFileAtomically(
      capture.dir() + "/" + ExpandPattern(kDetectionsPattern, "", id),
      FrameDetectionsJson(id, capture.manifest().cameras, result).dump(1) + "\n");
  summary->frames += 1;
  summary->views += n;
  summary->frames_with_hand += result.found ? 1 : 0;
  // Further hands are always found (3D hands): only the first may not be.
  const int hands = (result.found ? 1 : 0) + static_cast<int>(result.other_hands.size());
  summary->hands_found += hands;
  summary->frames_with_hands += hands > 1 ? 1 : 0;
  summary->frames_tracked += result.tracking == "track" ? 1 : 0;
  for (const ViewHandResult& r : result.views) {
    summary->views_detected += r.detected ? 1 : 0;
    summary->views_from_palm += (r.detected && r.source == "palm") ? 1 : 0;
    summary->views_tracked += (r.detected && r.source == "track") ? 1 : 0;
  }
  return result;
}

}  // namespace

DetectCaptureSummary DetectCapture(const std::string& capture_dir,
                                   const DetectCaptureOptions& options,
                                   const std::function<void(int, int)>& on_frame) {
  options.Check("detect");
  // A folder that is not a capture is named before any lock file is made in it (an
  // import beside may not have listed a frame yet: the lock names it below).
  ReadCaptureManifest(capture_dir,
                      "a native capture: `handlabel synth` or `capture "
                      "init` + `capture import` make one");
  const FileLock writer =
      LockFolderForWriting(capture_dir, "detect --capture", "--capture", "");
  // Read under the lock: as the last writer (an import) left it.
  const CaptureReader capture(capture_dir);
  if (capture.Has(kFileDetections) && !options.overwrite) {
    throw InputError(capture_dir + "/capture.json", "files.detections",
                     "no detections yet (pass --overwrite to replace them)",
                     capture.manifest().files.at(kFileDetections));
  }
  const auto t0 = std::chrono::steady_clock::now();
  const MediapipeHands detector(options.hands);
  std::filesystem::create_directories(capture_dir + "/detections");
  // Runs in parallel (per-frame mode: runs of one frame), a run's frames in order, each
  // model call on one thread (options.hands.num_threads): a frame's result depends on
  // its run's earlier frames only, so the files are the same at any count.
  DetectCaptureSummary summary;
  std::mutex mutex;  // summary and on_frame
  const int total = capture.num_frames();
  const std::vector<FrameRun> runs =
      FrameRuns(total, options.video ? options.palm_every : 1);
  const int workers =
      options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  // Workers take the next run until none is left; the governor parks all but the first
  // while other processes keep the cores busy (core/worker_governor.h).
  WorkerGovernorOptions governed;
  governed.calibration = std::chrono::milliseconds(30);
  WorkerGovernor governor(workers, governed);
  governor.Calibrate();
  std::atomic<size_t> next_run{0};
  const auto detect_run = [&](size_t k) {
    std::optional<FrameHandResult> previous;
    for (int f = runs[k].begin; f < runs[k].end; ++f) {
      DetectCaptureSummary frame;
      previous = DetectFrame(capture, f, detector, options,
                             previous ? &*previous : nullptr, &frame);
      const std::lock_guard<std::mutex> lock(mutex);
      summary.Add(frame);
      if (on_frame) on_frame(summary.frames, total);
    }
  };
  tbb::task_arena arena(workers);
  arena.execute([&] {
    tbb::parallel_for(0, workers, [&](int worker) {
      while (next_run.load() < runs.size()) {
        if (!governor.MayRun(worker)) {
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
          continue;
        }
        const size_t k = next_run.fetch_add(1);
        // Isolated: while a run waits for its views' tasks, its thread must not take up
        // another worker's loop (a parked one would then sleep on top of this run).
        if (k < runs.size()) tbb::this_task_arena::isolate([&] { detect_run(k); });
      }
    });
  });
  summary.worker_parks = governor.parks();
  ListDetections(capture);
  summary.seconds = SecondsSince(t0);
  return summary;
}

}  // namespace handlabel
