#pragma once
// `handlabel detect --capture C`: multi-view hand finding
// (network/detector/hand_detector.h) on every frame of a native capture, written as the
// capture's detections (detections/{frame}.json, docs/capture-format.md) with
// per-keypoint confidence, handedness, presence, and per view the reason when there is no
// detection. The manifest (capture.json) then lists the detections kind.
// docs/detector.md.

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "network/detector/hand_detector.h"
#include "network/detector/mediapipe_hands.h"

namespace handlabel {

struct DetectCaptureOptions {
  MediapipeHandsOptions hands;
  MultiViewDetectorOptions multiview;
  // Replace detections the capture already has (e.g. a synthetic capture's simulated
  // ones); without it such a capture is refused, so nothing written is lost.
  bool overwrite = false;
  // When set, also a picture per view of what was found
  // (network/detector/detector_overlay.h): <overlays_dir>/<frame>/<camera>.png.
  std::string overlays_dir;
  // Frames detected at once; 0 = one per core. Each runs its models on
  // hands.num_threads LibTorch threads (1 by default).
  int threads = 0;
  // Video mode (docs/detector.md): the frames in runs of consecutive frames, each frame
  // after a run's first with its regions from the previous frame's 3D hand
  // (DetectHandInVideo); runs go in parallel, a run's frames in order, so the files are
  // the same at any thread count. Off: every frame from scratch.
  bool video = false;
  // With video: a run (palm detection in every view) starts at every frame whose
  // position in the capture is a multiple of this; 0 = at the first frame only.
  int palm_every = 30;
  // Throws InputError naming `source` when a field is out of range.
  void Check(const std::string& source) const;
};

struct DetectCaptureSummary {
  int frames = 0;
  int views = 0;              // frames x cameras
  int views_detected = 0;     // views with a detection
  int views_from_palm = 0;    // ... whose ROI came from their own palm
  int views_tracked = 0;      // ... whose ROI came from the previous frame (video mode)
  int frames_tracked = 0;     // frames whose regions came from the previous frame
  int frames_with_hand = 0;   // frames where a 3D hand was established
  int hands_found = 0;        // 3D hands established, over all frames (max_hands > 1)
  int frames_with_hands = 0;  // frames where more than one was
  // Times the workers but one were parked because other processes kept the cores busy
  // (core/worker_governor.h).
  int worker_parks = 0;
  double seconds = 0;
  // Adds another part's counts (not its seconds).
  void Add(const DetectCaptureSummary& other);
};

// Consecutive frames [begin, end) of a capture, detected in order in video mode.
struct FrameRun {
  int begin = 0, end = 0;
};
// Frames 0 .. total - 1 cut before every multiple of `palm_every` (0: one run).
std::vector<FrameRun> FrameRuns(int total, int palm_every);

// Runs every frame (options.threads at once); `on_frame(done, total)` after each,
// one call at a time. Holds the capture folder's
// writer lock (core/file_lock.h) throughout: an import or another detect on the
// capture meanwhile is refused, as this one is while they run. Throws InputError naming
// the capture when it already has detections and `overwrite` is off.
DetectCaptureSummary DetectCapture(
    const std::string& capture_dir, const DetectCaptureOptions& options,
    const std::function<void(int, int)>& on_frame = nullptr);

// The detections record of one frame (native format plus the detector's fields).
nlohmann::json FrameDetectionsJson(const std::string& frame,
                                   const std::vector<std::string>& cameras,
                                   const FrameHandResult& result);

}  // namespace handlabel
