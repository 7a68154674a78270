#include "pipeline/detect_frame_source.h"

#include <chrono>

#include "capture/frame_images.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/stopwatch.h"
#include "pipeline/label_outputs.h"

namespace handlabel {

void DetectionStore::Put(const std::string& frame, FrameHandResult result) {
  std::lock_guard<std::mutex> lock(mutex_);
  results_[frame] = std::move(result);
}

std::optional<FrameHandResult> DetectionStore::Take(const std::string& frame) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = results_.find(frame);
  if (it == results_.end()) return std::nullopt;
  FrameHandResult result = std::move(it->second);
  results_.erase(it);
  return result;
}

std::optional<FrameHandResult> DetectionStore::Find(const std::string& frame) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = results_.find(frame);
  if (it == results_.end()) return std::nullopt;
  return it->second;
}

void DetectionStore::TakeAndWrite(const std::string& output_dir,
                                  const FrameInput& frame) {
  const std::optional<FrameHandResult> result = Take(frame.id);
  if (!result) return;
  std::vector<std::string> cameras;
  for (const RigCamera& camera : frame.rig.cameras()) cameras.push_back(camera.name);
  WriteFileAtomically(JobDetectionsPath(output_dir, frame.id),
                      FrameDetectionsJson(frame.id, cameras, *result).dump(1) + "\n");
}

void AddDetectorSeconds(const FrameHandResult& result, double seconds,
                        StageSeconds* times) {
  double palm = 0, landmarks = 0;
  for (const ViewHandResult& view : result.views) {
    palm += view.palm_seconds;
    landmarks += view.landmarks_seconds;
  }
  // Views that ran in parallel (video mode) may sum to more than the wall time.
  const double models = palm + landmarks;
  const double scale = models > seconds ? seconds / models : 1.0;
  (*times)["detect.palm"] += palm * scale;
  (*times)["detect.landmarks"] += landmarks * scale;
  (*times)["detect.other"] += seconds - models * scale;
}

std::string EvidenceHandName(const FrameHandResult& result, int index) {
  const int count = 1 + static_cast<int>(result.other_hands.size());
  if (result.max_hands == 1) return "";
  return "hand " + std::to_string(index + 1) + " of " + std::to_string(count) + " (" +
         HandSideName(HandAt(result, index).side) + ")";
}

std::vector<std::optional<Keypoints2d>> KeypointsFromDetection(
    const FrameHandResult& result) {
  std::vector<std::optional<Keypoints2d>> out;
  for (const ViewHandResult& view : result.views) {
    Keypoints2d keypoints;  // every view has an entry, as in a detections file
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      const double confidence = view.keypoints.confidence(k);
      if (!(confidence > 0) || !view.keypoints.uv_px.row(k).allFinite()) continue;
      keypoints.uv_px.row(k) = view.keypoints.uv_px.row(k);
      keypoints.confidence(k) = confidence;
    }
    out.push_back(keypoints);
  }
  return out;
}

DetectorFrameSource::DetectorFrameSource(std::unique_ptr<FrameSource> inner,
                                         const DetectCaptureOptions& options,
                                         std::shared_ptr<DetectionStore> store,
                                         bool detect_on_load)
    : Replaced2dFrameSource(std::move(inner)),
      options_(options),
      detect_on_load_(detect_on_load),
      store_(std::move(store)) {
  options_.Check("evidence.keypoints_2d: detector");
  detector_ = std::make_unique<MediapipeHands>(options_.hands);
}

FrameInput DetectorFrameSource::Load(const std::string& id) const {
  FrameInput frame = inner_->Load(id);
  if (frame.image_paths.size() != frame.rig.size()) {
    throw InputError(Describe(), "images", "one image per camera for the detector",
                     std::to_string(frame.image_paths.size()) + " for " +
                         std::to_string(frame.rig.size()) + " cameras");
  }
  DecodeFrameImages(&frame);  // kept in the frame for the network and the overlays
  for (size_t c = 0; c < frame.rig.size(); ++c) {
    if (frame.images[c].empty()) {
      throw InputError(Describe(), "images", "one image per camera for the detector",
                       "none for camera " + frame.rig[c].name);
    }
  }
  // The capture's own 2D (if any) is not this job's evidence.
  frame.keypoints_2d.clear();
  frame.evidence_hand.clear();
  if (detect_on_load_) Detect(&frame);
  return frame;
}

FrameHandResult DetectorFrameSource::Detect(FrameInput* frame,
                                            const FrameHandResult* previous) const {
  const auto start = std::chrono::steady_clock::now();
  // Frames may be detected in parallel: the models keep no state between calls and
  // each call runs on options_.hands.num_threads threads (1 by default).
  FrameHandResult result = options_.video
                               ? DetectHandInVideo(*detector_, frame->rig, frame->images,
                                                   previous, options_.multiview)
                               : DetectHandMultiView(*detector_, frame->rig,
                                                     frame->images, options_.multiview);
  // Several hands (multiview.max_hands > 1): the capture's hand.
  const HandSide wanted = side().value_or(HandSide::kRight);
  const int hand = HandIndexOfSide(result, wanted);
  if (hand >= 0) {
    frame->keypoints_2d = KeypointsFromDetection(HandAt(result, hand));
    frame->evidence_hand = EvidenceHandName(result, hand);
  } else {  // not the other hand: no 2D, the frame fails as one without a detection
    frame->keypoints_2d.assign(result.views.size(), std::nullopt);
    frame->evidence_hand = "no " + HandSideName(wanted) + " hand among " +
                           std::to_string(1 + result.other_hands.size()) + " found";
  }
  AddDetectorSeconds(result, SecondsSince(start), &frame->stage_seconds);
  if (store_) store_->Put(frame->id, result);
  return result;
}

std::string DetectorFrameSource::KeypointsSource() const {
  std::string text = "detector (MediaPipe Hands, model " + options_.hands.model;
  if (options_.video) {
    text += ", video mode: palm detection where a run starts (";
    if (options_.palm_every > 0) {
      text += "every " + std::to_string(options_.palm_every) + " frames, ";
    }
    text += "shard starts, gaps) and where the track is lost";
  }
  return text + ")";
}

}  // namespace handlabel
