#include "pipeline/label_policy.h"

#include <algorithm>
#include <chrono>

#include "core/errors.h"
#include "core/random.h"
#include "core/stage_times.h"
#include "pipeline/frame_metrics.h"
#include "pipeline/quality_checks.h"

namespace handlabel {
namespace {

void AddMetrics(const std::string& group, const Points3d& keypoints,
                const Points3d& vertices, const FrameGroundTruth& truth,
                FrameOutcome* outcome) {
  for (const auto& [name, value] : HandErrors(keypoints, vertices, truth)) {
    outcome->metrics[group + "/" + name] = value;
  }
  outcome->keypoints[group] = keypoints;
  outcome->keypoints[kTruthKeypoints] = truth.keypoints;
}

}  // namespace

uint64_t FrameSeed(uint64_t job_seed, const std::string& frame) {
  // FNV-1a of the id, then the SplitMix64 finaliser.
  return SplitMix64Finalize(job_seed + kSplitMix64Gamma * (Fnv1a64(frame) | 1));
}

Points3d NativeJointsFromKeypoints(const Points3d& keypoints) {
  HL_CHECK(keypoints.rows() == kNumHandKeypoints, "21 keypoints");
  Points3d joints(kNumHandJoints, 3);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int native = kSnapFromNative[k];
    if (native < kNumHandJoints) joints.row(native) = keypoints.row(k);
  }
  return joints;
}

std::vector<std::optional<Keypoints2d>> FitEvidence(const JobConfig& job,
                                                    const FrameInput& frame,
                                                    const MeshPrediction* prediction,
                                                    int* file_views) {
  const size_t views = frame.rig.size();
  std::vector<std::optional<Keypoints2d>> evidence(views);
  const bool use_files = job.keypoints != KeypointSource::kNetwork;
  const bool use_network = job.keypoints != KeypointSource::kFiles;
  if (use_files && !frame.keypoints_2d.empty()) {
    HL_CHECK(frame.keypoints_2d.size() == views, "one keypoint entry per view");
    evidence = frame.keypoints_2d;
  }
  std::vector<bool> from_files(views);
  for (size_t v = 0; v < views; ++v) from_files[v] = evidence[v].has_value();
  const bool any_files =
      std::find(from_files.begin(), from_files.end(), true) != from_files.end();
  if (use_network && prediction) {
    HL_CHECK(prediction->keypoints_2d.size() == views, "one 2D prediction per view");
    for (size_t v = 0; v < views; ++v) {
      if (evidence[v]) continue;
      evidence[v] = prediction->keypoints_2d[v];
      if (any_files) evidence[v]->confidence *= kNetworkFillInConfidence;
    }
  }
  for (const std::string& name : job.ignore_views) {
    const int v = frame.rig.IndexOf(name);
    if (v < 0) {
      throw InputError(job.source_file, "evidence.ignore_views",
                       "camera names of the capture", "'" + name + "'");
    }
    evidence[v].reset();
    from_files[v] = false;
  }
  if (file_views) {
    *file_views =
        static_cast<int>(std::count(from_files.begin(), from_files.end(), true));
  }
  for (const auto& view : evidence) {
    if (view) return evidence;
  }
  throw Error(std::string("no 2D keypoints to fit to (evidence.keypoints_2d: ") +
              (job.keypoints == KeypointSource::kFiles
                   ? "files, and the capture has none "
                     "for this frame"
               : job.keypoints == KeypointSource::kNetwork
                   ? "network, and the network did not run"
                   : "both, and neither has any") +
              ")");
}

namespace {

// One frame's labelling steps: choose the label (network, refined or fitted), then
// evaluate it against ground truth.
class FrameLabeler {
 public:
  FrameLabeler(const LabelContext& context, const FrameInput& frame,
               const MeshPrediction* prediction, uint64_t seed,
               const HandParams* previous)
      : context_(context),
        job_(*context.job),
        frame_(frame),
        prediction_(prediction),
        seed_(seed),
        previous_(previous) {}

  FrameOutcome Run() {
    FrameOutcome outcome;
    times_ = &outcome.stage_seconds;
    LabelRecord& label = outcome.label;
    label.frame = frame_.id;
    label.side = context_.side;
    label.provenance = context_.provenance;
    label.fit = nullptr;
    if (prediction_) {
      // The frame's file 2D judge the answer too, where the job uses them.
      const bool files = job_.keypoints != KeypointSource::kNetwork;
      StageTimer timer(times_, "checks");
      label.quality = CheckPrediction(frame_.rig, *prediction_, job_.quality,
                                      files ? &frame_.keypoints_2d : nullptr);
    }
    Choose(&label);
    if (!label.mesh.vertices.array().isFinite().all() ||
        !label.mesh.keypoints.array().isFinite().all()) {
      throw Error("the " + ToString(label.path) + " result is not finite");
    }
    if (job_.evaluate && frame_.ground_truth) {
      StageTimer timer(times_, "evaluate");
      Evaluate(&outcome);
    }
    return outcome;
  }

 private:
  // A fit from `init` (the network's mesh) or, with nullptr, from 2D evidence alone.
  // `times` (optional) gets the fitter's stages as "fit.<stage>" and the rest of this
  // call (the evidence per view) as "fit.other".
  LabelFit Fit(const MeshPrediction* init, StageSeconds* times) const {
    if (!context_.fitter) throw Error("refine.mode needs a fitter, and none was built");
    const auto start = std::chrono::steady_clock::now();
    LabelFit fit = FitWithoutTimes(init);
    if (times) {
      AddStageSeconds(fit.stage_seconds, times, "fit.");
      (*times)["fit.other"] +=
          std::max(0.0, SecondsSince(start) - TotalStageSeconds(fit.stage_seconds));
    }
    return fit;
  }

  LabelFit FitWithoutTimes(const MeshPrediction* init) const {
    LabelFitRequest request;
    request.frame = &frame_;
    request.init = init;
    request.keypoints_2d = FitEvidence(job_, frame_, prediction_, &request.file_views);
    if (job_.masks == MaskSource::kNetwork && prediction_)
      request.masks = prediction_->masks;
    request.previous = previous_;
    request.seed = seed_;
    return context_.fitter->Fit(request);
  }

  // The policy of label_policy.h.
  void Choose(LabelRecord* label) const {
    const bool accept_network =
        prediction_ &&
        (job_.refine_mode == RefineMode::kOff ||
         (job_.refine_mode == RefineMode::kFallback && label->quality.Passed()));
    if (accept_network) {
      label->path = LabelPath::kNetwork;
      label->params = prediction_->params;
      label->mesh.vertices = prediction_->vertices;
      label->mesh.keypoints = prediction_->keypoints;
      label->mesh.joints = NativeJointsFromKeypoints(prediction_->keypoints);
      return;
    }
    if (job_.refine_mode == RefineMode::kOff) {
      throw Error("refine.mode is off and there is no network prediction");
    }
    const bool refine = prediction_ && job_.refine_mode == RefineMode::kAlways;
    LabelFit result = Fit(refine ? prediction_ : nullptr, times_);
    label->path = refine ? LabelPath::kRefined : LabelPath::kFallbackFit;
    label->params = result.params;
    label->mesh = std::move(result.mesh);
    label->fit = std::move(result.report);
    if (!prediction_ && job_.refine_mode == RefineMode::kFallback) {
      label->fit["why"] = "no network";
    } else if (!refine) {
      label->fit["why"] = "quality checks failed: " + label->quality.FailedNames();
    }
  }

  void Evaluate(FrameOutcome* outcome) const {
    const FrameGroundTruth& truth = *frame_.ground_truth;
    const LabelRecord& label = outcome->label;
    AddMetrics("labels", label.mesh.keypoints, label.mesh.vertices, truth, outcome);
    AddMetrics(ToString(label.path), label.mesh.keypoints, label.mesh.vertices, truth,
               outcome);
    if (prediction_ && prediction_->keypoints.array().isFinite().all()) {
      AddMetrics("network_raw", prediction_->keypoints, prediction_->vertices, truth,
                 outcome);
    }
    if (!job_.baseline || !context_.fitter) return;
    if (label.path == LabelPath::kFallbackFit) {
      AddMetrics("fit_only", label.mesh.keypoints, label.mesh.vertices, truth, outcome);
      return;
    }
    // The baseline is for comparison only; its failure does not fail the frame.
    try {
      const LabelFit baseline = Fit(nullptr, nullptr);  // in "evaluate"
      AddMetrics("fit_only", baseline.mesh.keypoints, baseline.mesh.vertices, truth,
                 outcome);
    } catch (const std::exception&) {
    }
  }

  const LabelContext& context_;
  const JobConfig& job_;
  const FrameInput& frame_;
  const MeshPrediction* prediction_;
  const uint64_t seed_;
  const HandParams* previous_;
  StageSeconds* times_ = nullptr;  // the outcome's (Run)
};

}  // namespace

FrameOutcome LabelFrame(const LabelContext& context, const FrameInput& frame,
                        const MeshPrediction* prediction, uint64_t seed,
                        const HandParams* previous) {
  return FrameLabeler(context, frame, prediction, seed, previous).Run();
}

}  // namespace handlabel
