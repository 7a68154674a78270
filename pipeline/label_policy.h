#pragma once
// The fallback policy for one frame: which stage's answer becomes the label.
//   refine.mode off       the network's mesh (quality flags recorded, never replaced)
//   refine.mode always    the fitter refines the network's mesh against the 2D evidence;
//                         without a network it fits from the 2D evidence alone
//   refine.mode fallback  the network's mesh if it passes every quality check,
//                         otherwise a fit from the 2D evidence alone
// Also evaluates against ground truth (job output.evaluate) and runs the fit-only
// baseline (output.baseline).

#include <map>
#include <string>

#include "pipeline/job_config.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stages.h"

namespace handlabel {

// What one frame needs besides its input: the stages and the fixed provenance.
struct LabelContext {
  const JobConfig* job = nullptr;
  const LabelFitter* fitter = nullptr;  // nullptr when refine.mode is off
  HandSide side = HandSide::kRight;
  Provenance provenance;  // the same for every frame of the job
};

struct FrameOutcome {
  LabelRecord label;
  std::map<std::string, double> metrics;  // "<group>/<metric>" (label_summary.h)
  // With ground truth: the keypoints each metric group was scored on, and the truth's
  // ("truth"), for the motion metrics over consecutive frames (label_summary.h).
  std::map<std::string, Points3d> keypoints;
  // Where the frame's labelling time went (core/stage_times.h): "checks" (the network
  // answer's quality checks), "fit.<stage>" (LabelFit::stage_seconds, and "fit.other":
  // the rest of the fit call), "evaluate" (against ground truth, with the fit-only
  // baseline). Stages that did not run are absent.
  StageSeconds stage_seconds;
};

// Where the network's own 2D fills a view that has no file 2D while other views do,
// its confidences count this much: they are heatmap peaks, sure of themselves even when
// the answer is centimetres off, and must not outvote a detector's views.
constexpr double kNetworkFillInConfidence = 0.25;

// The 2D evidence for the fitter per job field evidence.keypoints_2d: the network's
// keypoints, the capture's keypoint files, or both (files where a view has one, else
// the network's, at kNetworkFillInConfidence when some view has files); none for the
// cameras of evidence.ignore_views. `file_views` (optional) gets how many views hold
// file 2D. Throws Error when the chosen source has nothing for this frame, InputError
// for an unknown camera name.
std::vector<std::optional<Keypoints2d>> FitEvidence(const JobConfig& job,
                                                    const FrameInput& frame,
                                                    const MeshPrediction* prediction,
                                                    int* file_views = nullptr);

// Labels one frame. `prediction` is nullptr when the job has no network; `previous` is
// the previous frame's label parameters when the job fits from them (fit.init:
// previous), else nullptr. Throws when the frame cannot be labelled (the runner
// records the message as the reason).
FrameOutcome LabelFrame(const LabelContext& context, const FrameInput& frame,
                        const MeshPrediction* prediction, uint64_t seed,
                        const HandParams* previous = nullptr);

// The deterministic per-frame seed: the job's seed mixed with the frame id.
uint64_t FrameSeed(uint64_t job_seed, const std::string& frame);

// 16 native joints from 21 SNAP keypoints (the joints are a subset of the keypoints).
Points3d NativeJointsFromKeypoints(const Points3d& keypoints);

}  // namespace handlabel
