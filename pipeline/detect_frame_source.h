#pragma once
// A label job's `evidence.keypoints_2d: detector` (docs/labeling-jobs.md): the frames of
// any capture reader with their 2D keypoints from MediaPipe Hands, run on the frame's
// images as it is loaded (multi-view hand finding, network/detector/hand_detector.h),
// exactly as `handlabel detect --capture` would write them (pipeline/detect_capture.h): a
// keypoint with confidence 0 is unknown (position 0), a view without a detection has
// none. The detector's full answer per frame stays available (DetectionStore) to the
// overlay writer, which draws it (network/detector/detector_overlay.h), and to the job,
// which writes it beside the labels (label_outputs.h: detections/<frame>.json).

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "capture/replaced_2d_frame_source.h"
#include "network/detector/hand_detector.h"
#include "pipeline/detect_capture.h"

namespace handlabel {

// The detector's answers per frame id, filled by DetectorFrameSource; thread-safe.
class DetectionStore {
 public:
  void Put(const std::string& frame, FrameHandResult result);
  // The frame's answer, removed from the store (each is written once: a long job
  // does not keep them all); nullopt when the frame was not detected (yet).
  std::optional<FrameHandResult> Take(const std::string& frame);
  // A copy of the frame's answer, left in the store (for the overlays, drawn before the
  // answer is written and taken).
  std::optional<FrameHandResult> Find(const std::string& frame) const;
  // Takes the frame's answer and writes it as `handlabel detect` would, to
  // <output_dir>/detections/<frame>.json (label_outputs.h); nothing when the frame was
  // not detected.
  void TakeAndWrite(const std::string& output_dir, const FrameInput& frame);

 private:
  mutable std::mutex mutex_;
  std::map<std::string, FrameHandResult> results_;
};

// The detector's wall time on a frame (`seconds`) into `times` as "detect.palm" and
// "detect.landmarks" (the models' calls, summed over views; scaled down to `seconds`
// where views ran in parallel) and "detect.other" (the rest: palm matching,
// triangulation, ROI placement, checks).
void AddDetectorSeconds(const FrameHandResult& result, double seconds,
                        StageSeconds* times);

// The 2D keypoints of one frame's detection in rig order, as the detections file of
// `handlabel detect` gives them to a job (unknown keypoints: confidence 0, position 0;
// views without a detection: nullopt).
std::vector<std::optional<Keypoints2d>> KeypointsFromDetection(
    const FrameHandResult& result);

// Which hand of `result` (HandAt's `index`) a job took, as the frame log says it:
// "hand 2 of 2 (left)", as DetectionsHandChoice::Describe (capture_format.h) for a file;
// "" when one hand was looked for.
std::string EvidenceHandName(const FrameHandResult& result, int index);

class DetectorFrameSource : public Replaced2dFrameSource {
 public:
  // Loads the models (InputError naming the file when one is missing). `store` may be
  // null (nothing kept). With `detect_on_load` false, Load only reads and decodes: the
  // caller detects the frames it needs with Detect (a job that tracks the hand,
  // evidence.detector_every, or detects in video mode, options.video).
  DetectorFrameSource(std::unique_ptr<FrameSource> inner,
                      const DetectCaptureOptions& options,
                      std::shared_ptr<DetectionStore> store, bool detect_on_load = true);
  // Reads the frame's images (InputError naming a file that cannot be read or does not
  // fit its camera) and detects unless told not to. Several frames may load at once.
  FrameInput Load(const std::string& id) const override;
  // Detects the hand in a frame that Load read: sets frame->keypoints_2d (with several
  // hands, options.multiview.max_hands > 1: those of the capture's side, HandIndexOfSide,
  // none when no hand of that side was found, and frame->evidence_hand) and returns the
  // detector's answer. Video mode (options.video): `previous` is the answer on the
  // previous frame of the run (nullptr on a run's first frame, DetectHandInVideo).
  FrameHandResult Detect(FrameInput* frame,
                         const FrameHandResult* previous = nullptr) const;
  std::string KeypointsSource() const override;

 private:
  DetectCaptureOptions options_;
  bool detect_on_load_ = true;
  std::unique_ptr<MediapipeHands> detector_;
  std::shared_ptr<DetectionStore> store_;
};

}  // namespace handlabel
