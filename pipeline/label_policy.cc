#include "pipeline/label_policy.h"

#include "core/errors.h"
#include "core/random.h"
#include "pipeline/frame_metrics.h"
#include "pipeline/quality_checks.h"

namespace handlabel {
namespace {

void AddMetrics(const std::string& group, const Points3d& keypoints,
                const Points3d& vertices, const FrameGroundTruth& truth,
                std::map<std::string, double>* metrics) {
  for (const auto& [name, value] : HandErrors(keypoints, vertices, truth)) {
    (*metrics)[group + "/" + name] = value;
  }
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

std::vector<std::optional<Keypoints2dView>> FitEvidence(
    const JobConfig& job, const FrameInput& frame, const MeshPrediction* prediction) {
  const size_t views = frame.rig.size();
  std::vector<std::optional<Keypoints2dView>> evidence(views);
  const bool use_files = job.keypoints != KeypointSource::kNetwork;
  const bool use_network = job.keypoints != KeypointSource::kFiles;
  if (use_files && !frame.keypoints_2d.empty()) {
    HL_CHECK(frame.keypoints_2d.size() == views, "one keypoint entry per view");
    evidence = frame.keypoints_2d;
  }
  if (use_network && prediction) {
    HL_CHECK(prediction->keypoints_2d.size() == views, "one 2D prediction per view");
    for (size_t v = 0; v < views; ++v) {
      if (!evidence[v]) evidence[v] = prediction->keypoints_2d[v];
    }
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

FrameOutcome LabelFrame(const LabelContext& context, const FrameInput& frame,
                        const MeshPrediction* prediction, uint64_t seed) {
  const JobConfig& job = *context.job;
  FrameOutcome outcome;
  LabelRecord& label = outcome.label;
  label.frame = frame.id;
  label.side = context.side;
  label.provenance = context.provenance;
  label.fit = nullptr;

  if (prediction) label.quality = CheckPrediction(frame.rig, *prediction, job.quality);
  const bool accept_network =
      prediction &&
      (job.refine_mode == RefineMode::kOff ||
       (job.refine_mode == RefineMode::kFallback && label.quality.Passed()));

  auto fit = [&](const MeshPrediction* init) {
    if (!context.fitter) throw Error("refine.mode needs a fitter, and none was built");
    LabelFitRequest request;
    request.frame = &frame;
    request.init = init;
    request.keypoints_2d = FitEvidence(job, frame, prediction);
    if (job.masks == MaskSource::kNetwork && prediction)
      request.masks = prediction->masks;
    request.seed = seed;
    return context.fitter->Fit(request);
  };

  if (accept_network) {
    label.path = LabelPath::kNetwork;
    label.params = prediction->params;
    label.mesh.vertices = prediction->vertices;
    label.mesh.keypoints = prediction->keypoints;
    label.mesh.joints = NativeJointsFromKeypoints(prediction->keypoints);
  } else if (job.refine_mode == RefineMode::kOff) {
    throw Error("refine.mode is off and there is no network prediction");
  } else {
    const bool refine = prediction && job.refine_mode == RefineMode::kAlways;
    LabelFit result = fit(refine ? prediction : nullptr);
    label.path = refine ? LabelPath::kRefined : LabelPath::kFallbackFit;
    label.params = result.params;
    label.mesh = std::move(result.mesh);
    label.fit = std::move(result.report);
    if (!prediction && job.refine_mode == RefineMode::kFallback) {
      label.fit["why"] = "no network";
    } else if (!refine) {
      label.fit["why"] = "quality checks failed: " + label.quality.FailedNames();
    }
  }
  if (!label.mesh.vertices.array().isFinite().all() ||
      !label.mesh.keypoints.array().isFinite().all()) {
    throw Error("the " + ToString(label.path) + " result is not finite");
  }

  if (job.evaluate && frame.ground_truth) {
    const FrameGroundTruth& truth = *frame.ground_truth;
    AddMetrics("labels", label.mesh.keypoints, label.mesh.vertices, truth,
               &outcome.metrics);
    AddMetrics(ToString(label.path), label.mesh.keypoints, label.mesh.vertices, truth,
               &outcome.metrics);
    if (prediction && prediction->keypoints.array().isFinite().all()) {
      AddMetrics("network_raw", prediction->keypoints, prediction->vertices, truth,
                 &outcome.metrics);
    }
    if (job.baseline && context.fitter) {
      if (label.path == LabelPath::kFallbackFit) {
        AddMetrics("fit_only", label.mesh.keypoints, label.mesh.vertices, truth,
                   &outcome.metrics);
      } else {
        // The baseline is for comparison only; its failure does not fail the frame.
        try {
          const LabelFit baseline = fit(nullptr);
          AddMetrics("fit_only", baseline.mesh.keypoints, baseline.mesh.vertices, truth,
                     &outcome.metrics);
        } catch (const std::exception&) {
        }
      }
    }
  }
  return outcome;
}

}  // namespace handlabel
