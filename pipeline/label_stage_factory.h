#pragma once
// Builds the stages of a labeling job from its config: the capture reader for
// input.format, the network for network.weights, the fitter for refine.mode (and
// output.baseline), the hand model and the overlay writer.

#include <memory>
#include <optional>
#include <string>

#include "hand/hand_model.h"
#include "pipeline/ceres_label_fitter.h"
#include "pipeline/detect_frame_source.h"
#include "pipeline/job_config.h"
#include "pipeline/label_job.h"
#include "pipeline/network_stage.h"

namespace handlabel {

struct BuiltLabelStages {
  std::unique_ptr<FrameSource> source;
  std::optional<NetworkStage> predictor;
  std::unique_ptr<LabelFitter> fitter;
  std::unique_ptr<OverlayWriter> overlays;
  HandModel hand_model;
  // Why the hand model is not the one asked for (ResolveHandModel's note), "" if nothing.
  std::string hand_model_note;
  // The detector on demand of a job that tracks (LabelStageSet::find_keypoints_2d).
  std::function<void(FrameInput*)> find_keypoints_2d;
  // The detector's tracks in video mode (LabelStageSet::start_video_track).
  std::function<std::function<void(FrameInput*)>()> start_video_track;
  // The detector's answers into the output (LabelStageSet::write_detections).
  std::function<void(const std::string&, const FrameInput&)> write_detections;
  // Views of the above for RunLabelJob.
  LabelStageSet Set() const;
};

// The fitter's settings from the job: fields of section `fit` that are set replace
// the fitter's defaults (the smoothing pass fits with the same, smooth_job.h).
CeresLabelFitterOptions FitterOptions(const JobConfig& job);

// Throws InputError naming the job file and the field whose stage cannot be built.
// `memo`: the network's answers shared with other jobs (network_stage.h).
BuiltLabelStages BuildLabelStages(const JobConfig& job,
                                  std::shared_ptr<PredictionMemo> memo = nullptr);

// Only the frame source (what `handlabel merge` needs to list the job's frames). With
// evidence.keypoints_2d: detector, the detector's answers go into `detections` when
// given, and `detector` (when given) points at the detecting source.
std::unique_ptr<FrameSource> BuildFrameSource(
    const JobConfig& job, std::shared_ptr<DetectionStore> detections = nullptr,
    const DetectorFrameSource** detector = nullptr);

}  // namespace handlabel
