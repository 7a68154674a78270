#include "pipeline/fit_capture.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/text.h"
#include "hand/hand_anatomy.h"
#include "pipeline/label_job.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stage_factory.h"

namespace handlabel {
namespace {

double Mean(const LabelSummary& s, const std::string& metric) {
  const auto group = s.metrics.find("labels");
  if (group == s.metrics.end()) return 0.0;
  const auto it = group->second.find(metric);
  return it == group->second.end() ? 0.0 : it->second.Mean();
}

// What the labels tell beyond the job summary: convergence and limit violations.
void ReadFitReports(const std::string& out_dir, const std::vector<std::string>& frames,
                    const HandModel& model, FitCaptureSummary* s) {
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  const HandLimits limits = DefaultHandLimits();
  for (const std::string& frame : frames) {
    const std::string path = LabelFilePath(out_dir, frame);
    if (!std::filesystem::exists(path)) continue;  // failed: in the job summary
    const LabelRecord label = ReadLabelFile(path);
    if (label.fit.is_object() && label.fit.value("converged", false)) ++s->converged;
    if (!label.params) continue;
    HandPoseVector angles;
    HandAnatomicalAngles(anatomy, label.params->hand_pose.data(), angles.data());
    s->max_limit_violation_deg =
        std::max(s->max_limit_violation_deg, MaxLimitViolationDeg(limits, angles));
  }
}

}  // namespace

void FitCaptureOptions::Check(const std::string& source) const {
  if (capture_dir.empty()) throw InputError(source, "--capture", "a capture folder");
  if (out_dir.empty()) throw InputError(source, "--out", "an output folder");
  RequireAtLeast(source, "--max-frames", max_frames, 0);
  if (evidence != "auto" && evidence != "detections" && evidence != "keypoints") {
    throw InputError(source, "--evidence", "auto, detections or keypoints", evidence);
  }
  if (object_masks != "files" && object_masks != "none")
    throw InputError(source, "--object-masks", "files or none", object_masks);
  if (masks != "auto" && masks != "detections" && masks != "truth" && masks != "none") {
    throw InputError(source, "--masks", "auto, detections, truth or none", masks);
  }
  if (fit.init.empty()) {
    throw InputError(source, "--init", "triangulate, gt, previous or a folder");
  }
  RequireAtLeast(source, "--threads", num_threads, 0);
}

namespace {

// The command's flag for each fitter field of the job it builds: errors name the flag
// the user typed, not a job field they never wrote.
std::string FlagOfFitField(const std::string& field) {
  static const std::map<std::string, std::string> flags = {
      {"fit.init", "--init"},
      {"fit.keypoint_loss", "--loss"},
      {"fit.keypoint_loss_scale", "--loss-scale"},
      {"fit.keypoint_sigma_px", "--keypoint-sigma"},
      {"fit.silhouette_sigma_px", "--silhouette-sigma"},
      {"fit.silhouette_rounds", "--silhouette-rounds"},
      {"fit.mask_margin_px", "--mask-margin"},
      {"fit.pose_pca_comps", "--pca"},
      {"fit.unknown_occluders", "--unknown-occluders"}};
  const auto it = flags.find(field);
  return it == flags.end() ? "" : it->second;
}

}  // namespace

JobConfig FitJob(const FitCaptureOptions& o) {
  o.Check("command line");
  JobConfig job;
  job.source_file = "handlabel fit";
  job.name = "fit";
  job.input_format = "native";
  job.input_path = std::filesystem::path(o.capture_dir).lexically_normal().string();
  if (!o.frames.empty()) job.frames = Join(o.frames, ",");
  job.max_frames = o.max_frames;
  job.hand_model = o.hand_model;
  job.threads = o.num_threads;
  job.refine_mode = RefineMode::kAlways;  // no network: every frame is fitted
  job.keypoints = KeypointSource::kFiles;
  job.keypoint_files = o.evidence;
  job.masks = o.masks == "none" ? MaskSource::kNone : MaskSource::kFiles;
  job.mask_files = o.masks == "none" ? "auto" : o.masks;
  job.object_masks = o.object_masks == "files";
  job.ignore_views = o.ignore_views;
  job.fit = o.fit;
  job.output_dir = o.out_dir;
  job.overlays = o.overlays;
  try {
    job.Check(job.source_file);
  } catch (const InputError& e) {
    const std::string flag = FlagOfFitField(e.field());
    if (flag.empty()) throw;
    throw InputError("command line", flag, e.expected(), e.got());
  }
  return job;
}

FitCaptureSummary FitCapture(const FitCaptureOptions& options, std::ostream* log) {
  const JobConfig job = FitJob(options);
  const BuiltLabelStages stages = BuildLabelStages(job);
  LabelRunOptions run;
  run.force = true;  // fit every chosen frame again, as the command always did
  run.log = log;
  FitCaptureSummary s;
  s.job = RunLabelJob(job, stages.Set(), run);
  s.frames = s.job.frames;
  s.mean_seconds = s.job.frame_seconds / std::max(1, s.job.frames);
  s.has_ground_truth = s.job.metrics.count("labels") > 0;
  s.mpjpe = Mean(s.job, "mpjpe_mm") / 1000;
  s.mpvpe = Mean(s.job, "mpvpe_mm") / 1000;
  s.pa_mpjpe = Mean(s.job, "pa_mpjpe_mm") / 1000;
  s.pa_mpvpe = Mean(s.job, "pa_mpvpe_mm") / 1000;
  s.auc_joints = Mean(s.job, "auc");
  s.summary_path = SummaryJsonPath(job.output_dir);
  s.hand_model_note = stages.hand_model_note;
  ReadFitReports(job.output_dir, JobFrames(job, *stages.source), stages.hand_model, &s);
  return s;
}

}  // namespace handlabel
