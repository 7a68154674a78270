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
  // Throws InputError naming `source` when a field is out of range.
  void Check(const std::string& source) const;
};

struct DetectCaptureSummary {
  int frames = 0;
  int views = 0;             // frames x cameras
  int views_detected = 0;    // views with a detection
  int views_from_palm = 0;   // ... whose ROI came from their own palm
  int frames_with_hand = 0;  // frames where a 3D hand was established
  double seconds = 0;
  // Adds another part's counts (not its seconds).
  void Add(const DetectCaptureSummary& other);
};

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
