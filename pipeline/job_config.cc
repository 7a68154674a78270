#include "pipeline/job_config.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <set>

#include "core/errors.h"
#include "core/option_checks.h"
#include "network/detector/mediapipe_hands.h"
#include "pipeline/yaml_section.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

template <typename E>
E ParseEnum(const std::string& text,
            const std::vector<std::pair<const char*, E>>& options,
            const std::string& file, const std::string& field) {
  std::string names;
  for (const auto& [name, value] : options) {
    if (text == name) return value;
    names += (names.empty() ? "" : " | ") + std::string(name);
  }
  throw InputError(file, field, names, "'" + text + "'");
}

std::string Resolve(const std::string& path, const fs::path& base) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return (base / path).lexically_normal().string();
}

// Fields that are absent stay unset (the fitter's default).
template <typename T>
void ReadOptional(Section& section, const char* key, std::optional<T>* value) {
  const YAML::Node node = section.Raw(key);
  if (!node || node.IsNull()) return;
  T read{};
  section.Read(key, &read);
  *value = read;
}

bool IsFitInitKeyword(const std::string& init) {
  return init == "triangulate" || init == "gt" || init == "previous";
}

void CheckFitSettings(const FitSettings& fit, const std::string& f) {
  if (!IsFitInitKeyword(fit.init) && !fs::is_directory(fit.init)) {
    throw InputError(
        f, "fit.init",
        "triangulate | gt | previous | a folder of per-frame parameter files",
        "'" + fit.init + "'");
  }
  if (fit.keypoint_loss && *fit.keypoint_loss != "cauchy" &&
      *fit.keypoint_loss != "huber" && *fit.keypoint_loss != "trivial") {
    throw InputError(f, "fit.keypoint_loss", "cauchy | huber | trivial",
                     "'" + *fit.keypoint_loss + "'");
  }
  const std::pair<const char*, const std::optional<double>*> positive[] = {
      {"fit.keypoint_loss_scale", &fit.keypoint_loss_scale},
      {"fit.keypoint_sigma_px", &fit.keypoint_sigma_px},
      {"fit.silhouette_sigma_px", &fit.silhouette_sigma_px}};
  for (const auto& [field, value] : positive) {
    if (*value) RequireGreater(f, field, **value, 0);
  }
  if (fit.mask_margin_px) {
    RequireInRange(f, "fit.mask_margin_px", *fit.mask_margin_px, 0, 50, "0..50 (pixels)");
  }
  if (fit.silhouette_rounds) {
    RequireAtLeast(f, "fit.silhouette_rounds", *fit.silhouette_rounds, 0);
  }
  if (fit.detector_keypoints && fit.detector_keypoints->empty()) {
    throw InputError(f, "fit.detector_keypoints",
                     "none, mediapipe or a detector keypoint model file", "\"\"");
  }
  if (fit.unknown_occluders && *fit.unknown_occluders != "one_sided" &&
      *fit.unknown_occluders != "two_sided") {
    throw InputError(f, "fit.unknown_occluders", "one_sided | two_sided",
                     "'" + *fit.unknown_occluders + "'");
  }
  if (fit.pose_pca_comps && *fit.pose_pca_comps != 0 && *fit.pose_pca_comps != 12 &&
      *fit.pose_pca_comps != 45) {
    throw InputError(f, "fit.pose_pca_comps", "0, 12 or 45",
                     std::to_string(*fit.pose_pca_comps));
  }
}

void CheckFileEvidence(const JobConfig& job, const std::string& f) {
  if (job.keypoint_files != "auto" && job.keypoint_files != "detections" &&
      job.keypoint_files != "keypoints") {
    throw InputError(f, "evidence.keypoint_files", "auto | detections | keypoints",
                     "'" + job.keypoint_files + "'");
  }
  if (job.mask_files != "auto" && job.mask_files != "detections" &&
      job.mask_files != "truth") {
    throw InputError(f, "evidence.mask_files", "auto | detections | truth",
                     "'" + job.mask_files + "'");
  }
  if (job.input_format != "native") {
    if (job.keypoint_files != "auto") {
      throw InputError(f, "evidence.keypoint_files",
                       "auto (the choice exists for input.format native only)",
                       "'" + job.keypoint_files + "'");
    }
    if (job.mask_files != "auto") {
      throw InputError(f, "evidence.mask_files",
                       "auto (the choice exists for input.format native only)",
                       "'" + job.mask_files + "'");
    }
  }
}

void ReadFitSection(Section& top, JobConfig* job) {
  Section fit = top.Child("fit");
  FitSettings& s = job->fit;
  fit.Read("init", &s.init);
  ReadOptional(fit, "keypoint_loss", &s.keypoint_loss);
  ReadOptional(fit, "keypoint_loss_scale", &s.keypoint_loss_scale);
  ReadOptional(fit, "keypoint_sigma_px", &s.keypoint_sigma_px);
  ReadOptional(fit, "silhouette_sigma_px", &s.silhouette_sigma_px);
  ReadOptional(fit, "silhouette_rounds", &s.silhouette_rounds);
  ReadOptional(fit, "mask_margin_px", &s.mask_margin_px);
  ReadOptional(fit, "pose_pca_comps", &s.pose_pca_comps);
  ReadOptional(fit, "joint_limits", &s.joint_limits);
  ReadOptional(fit, "optimise_shape", &s.optimise_shape);
  ReadOptional(fit, "silhouette_check", &s.silhouette_check);
  ReadOptional(fit, "unknown_occluders", &s.unknown_occluders);
  ReadOptional(fit, "detector_keypoints", &s.detector_keypoints);
  fit.RejectUnknownKeys();
}

void ReadSequenceSection(Section& top, JobConfig* job) {
  Section sequence = top.Child("sequence");
  SequenceSettings& s = job->sequence;
  sequence.Read("smooth", &s.smooth);
  sequence.Read("window", &s.window);
  sequence.Read("overlap", &s.overlap);
  sequence.Read("acceleration_sigma_mm", &s.acceleration_sigma_mm);
  sequence.Read("iterations", &s.iterations);
  sequence.Read("detector_keypoints", &s.detector_keypoints);
  sequence.RejectUnknownKeys();
}

void ReadRefineSection(Section& top, const std::string& path, JobConfig* job) {
  Section refine = top.Child("refine");
  std::string mode = "fallback";
  refine.Read("mode", &mode);
  job->refine_mode = ParseEnum<RefineMode>(mode,
                                           {{"off", RefineMode::kOff},
                                            {"always", RefineMode::kAlways},
                                            {"fallback", RefineMode::kFallback}},
                                           path, refine.Name("mode"));
  refine.Read("max_reprojection_px", &job->quality.max_reprojection_px);
  refine.Read("max_view_disagreement_mm", &job->quality.max_view_disagreement_mm);
  refine.Read("max_detector_rms_px", &job->quality.max_detector_rms_px);
  refine.Read("min_confidence", &job->quality.min_confidence);
  refine.Read("min_views", &job->quality.min_views);
  refine.Read("min_hand_span_m", &job->quality.min_hand_span_m);
  refine.Read("max_hand_span_m", &job->quality.max_hand_span_m);
  refine.Read("network_sigma_mm", &job->refine_network_sigma_mm);
  refine.Read("restart_px", &job->refine_restart_px);
  refine.RejectUnknownKeys();
}

void ReadEvidenceSection(Section& top, const std::string& path, JobConfig* job) {
  Section evidence = top.Child("evidence");
  std::string keypoints = "network", masks = "files";
  evidence.Read("keypoints_2d", &keypoints);
  evidence.Read("masks", &masks);
  evidence.Read("network_mask_sigma_px", &job->network_mask_sigma_px);
  evidence.Read("keypoint_files", &job->keypoint_files);
  evidence.Read("mask_files", &job->mask_files);
  std::string object_masks = "files";
  evidence.Read("object_masks", &object_masks);
  if (object_masks != "files" && object_masks != "none") {
    throw InputError(path, evidence.Name("object_masks"), "files | none",
                     "'" + object_masks + "'");
  }
  job->object_masks = object_masks == "files";
  evidence.Read("ignore_views", &job->ignore_views);
  evidence.Read("detections", &job->detections);
  evidence.Read("detector_model", &job->detector_model);
  evidence.Read("detector_palm_tiles", &job->detector_palm_tiles);
  ParsePalmTiles(job->detector_palm_tiles, path, evidence.Name("detector_palm_tiles"));
  evidence.Read("detector_every", &job->detector_every);
  std::string detector_mode = "frame";
  evidence.Read("detector_mode", &detector_mode);
  if (detector_mode != "frame" && detector_mode != "video") {
    throw InputError(path, evidence.Name("detector_mode"), "frame | video",
                     "'" + detector_mode + "'");
  }
  job->detector_video = detector_mode == "video";
  evidence.Read("detector_palm_every", &job->detector_palm_every);
  evidence.Read("detector_max_hands", &job->detector_max_hands);
  if (job->detector_model != "full" && job->detector_model != "lite") {
    throw InputError(path, evidence.Name("detector_model"), "full | lite",
                     "'" + job->detector_model + "'");
  }
  if (keypoints != "network" && keypoints != "files" && keypoints != "both" &&
      keypoints != "detector") {
    throw InputError(path, evidence.Name("keypoints_2d"),
                     "network | files | both | detector", "'" + keypoints + "'");
  }
  if (keypoints == "detector") {
    keypoints = "files";  // the detector's 2D is file-like evidence from here on
    job->keypoints_from_detector = true;
    if (!job->detections.empty()) {
      throw InputError(path, evidence.Name("detections"),
                       "empty with keypoints_2d: detector (one source of 2D)",
                       "'" + job->detections + "'");
    }
  }
  if (!(job->network_mask_sigma_px >= 0)) {
    throw InputError(path, evidence.Name("network_mask_sigma_px"),
                     "> 0 pixels, or 0 for the default",
                     std::to_string(job->network_mask_sigma_px));
  }
  job->keypoints = ParseEnum<KeypointSource>(keypoints,
                                             {{"network", KeypointSource::kNetwork},
                                              {"files", KeypointSource::kFiles},
                                              {"both", KeypointSource::kBoth}},
                                             path, evidence.Name("keypoints_2d"));
  job->masks = ParseEnum<MaskSource>(masks,
                                     {{"none", MaskSource::kNone},
                                      {"files", MaskSource::kFiles},
                                      {"network", MaskSource::kNetwork}},
                                     path, evidence.Name("masks"));
  if (job->network_mask_sigma_px == 0) {
    job->network_mask_sigma_px = job->keypoints == KeypointSource::kNetwork ? 2.0 : 16.0;
  }
  evidence.RejectUnknownKeys();
}

}  // namespace

bool FitSettings::IsDefault() const {
  return init == "triangulate" && !keypoint_loss && !keypoint_loss_scale &&
         !keypoint_sigma_px && !silhouette_sigma_px && !silhouette_rounds &&
         !pose_pca_comps && !joint_limits && !optimise_shape && !silhouette_check &&
         !unknown_occluders && !mask_margin_px && !detector_keypoints;
}

std::string ToString(RefineMode mode) {
  switch (mode) {
    case RefineMode::kOff:
      return "off";
    case RefineMode::kAlways:
      return "always";
    case RefineMode::kFallback:
      return "fallback";
  }
  return "?";
}

namespace {

// evidence.detector_every.
void CheckTracking(const JobConfig& job, const std::string& source) {
  RequireAtLeast(source, "evidence.detector_every", job.detector_every, 1);
  if (job.detector_every == 1) return;
  const std::string why = " (evidence.detector_every " +
                          std::to_string(job.detector_every) +
                          " tracks the hand: the detector runs only where needed)";
  if (!job.keypoints_from_detector) {
    throw InputError(source, "evidence.keypoints_2d", "detector" + why,
                     job.keypoints == KeypointSource::kNetwork ? "'network'"
                     : job.keypoints == KeypointSource::kFiles ? "'files'"
                                                               : "'both'");
  }
  if (job.network_weights.empty()) {
    throw InputError(source, "network.weights", "a network to track with" + why);
  }
  if (job.refine_mode != RefineMode::kFallback) {
    throw InputError(source, "refine.mode", "fallback" + why,
                     "'" + ToString(job.refine_mode) + "'");
  }
}

// evidence.detector_mode: video.
void CheckDetectorVideo(const JobConfig& job, const std::string& source) {
  RequireAtLeast(source, "evidence.detector_palm_every", job.detector_palm_every, 0,
                 ">= 0 (0 = palm detection only where the track is lost)");
  if (!job.detector_video) return;
  const std::string why = " (evidence.detector_mode video detects every frame in order)";
  if (!job.keypoints_from_detector) {
    throw InputError(source, "evidence.keypoints_2d", "detector" + why,
                     job.keypoints == KeypointSource::kNetwork ? "'network'"
                     : job.keypoints == KeypointSource::kFiles ? "'files'"
                                                               : "'both'");
  }
  if (job.detector_every != 1) {
    throw InputError(source, "evidence.detector_every", "1" + why,
                     std::to_string(job.detector_every));
  }
}

// evidence.detector_max_hands.
void CheckDetectorMaxHands(const JobConfig& job, const std::string& source) {
  RequireAtLeast(source, "evidence.detector_max_hands", job.detector_max_hands, 1);
  if (job.detector_max_hands == 1) return;
  const std::string got = std::to_string(job.detector_max_hands);
  if (!job.keypoints_from_detector) {
    throw InputError(source, "evidence.detector_max_hands",
                     "1 (hands are looked for by the job's detector: "
                     "evidence.keypoints_2d: detector)",
                     got);
  }
  if (job.detector_video) {
    throw InputError(source, "evidence.detector_max_hands",
                     "1 with evidence.detector_mode video (it tracks one hand)", got);
  }
}

}  // namespace

void JobConfig::Check(const std::string& source) const {
  const std::set<std::string> formats = {"native", "dexycb", "ho3d", "oakink"};
  if (!formats.count(input_format)) {
    throw InputError(source, "input.format", "native | dexycb | ho3d | oakink",
                     "'" + input_format + "'");
  }
  if (input_path.empty()) throw InputError(source, "input.path", "the capture folder");
  if (cameras_source != "capture" && cameras_source != "file") {
    throw InputError(source, "cameras.source", "capture | file",
                     "'" + cameras_source + "'");
  }
  if (cameras_source == "file" && cameras_file.empty()) {
    throw InputError(source, "cameras.file", "a rig file when cameras.source is file");
  }
  if (output_dir.empty()) throw InputError(source, "output.dir", "an output folder");
  RequireAtLeast(source, "network.batch_size", batch_size, 1);
  RequireAtLeast(source, "network.threads", threads, 0);
  if (network_precision != "fp32" && network_precision != "bf16" &&
      network_precision != "auto") {
    throw InputError(source, "network.precision", "fp32, bf16 or auto",
                     "'" + network_precision + "'");
  }
  if (network_weights.empty() && refine_mode != RefineMode::kAlways) {
    throw InputError(source, "refine.mode",
                     "'always' when network.weights is empty (without a network every "
                     "frame must be fitted)",
                     "'" + ToString(refine_mode) + "'");
  }
  if (network_weights.empty() && keypoints != KeypointSource::kFiles) {
    throw InputError(source, "evidence.keypoints_2d", "'files' when there is no network");
  }
  CheckTracking(*this, source);
  CheckDetectorVideo(*this, source);
  CheckDetectorMaxHands(*this, source);
  RequireGreater(source, "refine.max_reprojection_px", quality.max_reprojection_px, 0);
  RequireGreater(source, "refine.max_view_disagreement_mm",
                 quality.max_view_disagreement_mm, 0);
  RequireGreater(source, "refine.max_detector_rms_px", quality.max_detector_rms_px, 0);
  RequireInRange(source, "refine.min_confidence", quality.min_confidence, 0, 1,
                 "a value in [0, 1]");
  RequireAtLeast(source, "refine.min_views", quality.min_views, 1);
  RequireGreater(source, "refine.network_sigma_mm", refine_network_sigma_mm, 0);
  RequireAtLeast(source, "refine.restart_px", refine_restart_px, 0);
  if (!(quality.min_hand_span_m > 0 &&
        quality.max_hand_span_m > quality.min_hand_span_m)) {
    throw InputError(source, "refine.min_hand_span_m / max_hand_span_m",
                     "0 < min_hand_span_m < max_hand_span_m");
  }
  for (const std::string& m : meshes) {
    if (m != "ply" && m != "obj")
      throw InputError(source, "output.meshes", "ply and/or obj", "'" + m + "'");
  }
  if (overlay_format != "jpg" && overlay_format != "png") {
    throw InputError(source, "output.overlay_format", "jpg or png",
                     "'" + overlay_format + "'");
  }
  RequireAtLeast(source, "input.max_frames", max_frames, 0);
  CheckFileEvidence(*this, source);
  CheckFitSettings(fit, source);
  sequence.Check(source);
  if (sequence.smooth) CheckSmoothable();
}

void JobConfig::CheckSmoothable() const {
  if (keypoints == KeypointSource::kFiles &&
      (!keypoints_from_detector || detector_every == 1)) {
    return;
  }
  throw InputError(source_file, "evidence.keypoints_2d",
                   "2D that a smoothing pass can refit: files, or detector with "
                   "detector_every 1 (its answers are kept in <output.dir>/detections/)",
                   keypoints_from_detector
                       ? "detector with detector_every " + std::to_string(detector_every)
                   : keypoints == KeypointSource::kNetwork ? "network"
                                                           : "both");
}

void SequenceSettings::Check(const std::string& source) const {
  RequireAtLeast(source, "sequence.window", window, 3);
  RequireAtLeast(source, "sequence.overlap", overlap, 1);
  if (2 * overlap > window) {
    throw InputError(source, "sequence.overlap",
                     "at most half of sequence.window (" + std::to_string(window) + ")",
                     std::to_string(overlap));
  }
  RequireGreater(source, "sequence.acceleration_sigma_mm", acceleration_sigma_mm, 0);
  RequireAtLeast(source, "sequence.iterations", iterations, 1);
  if (detector_keypoints.empty()) {
    throw InputError(source, "sequence.detector_keypoints",
                     "none, mediapipe or a detector keypoint model file", "\"\"");
  }
}

JobConfig LoadJobConfig(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path, "", "a readable YAML job file", "cannot open it");
  } catch (const YAML::Exception& e) {
    throw InputError(path, "", "valid YAML", e.what());
  }
  JobConfig job;
  job.source_file = path;
  const fs::path base = fs::path(path).parent_path();

  Section top(root, path, "");
  top.Read("name", &job.name);
  top.Read("seed", &job.seed);
  top.Read("hand_model", &job.hand_model);

  Section input = top.Child("input");
  input.Read("format", &job.input_format);
  input.Read("path", &job.input_path);
  input.Read("frames", &job.frames);
  input.Read("max_frames", &job.max_frames);
  input.RejectUnknownKeys();

  Section cameras = top.Child("cameras");
  cameras.Read("source", &job.cameras_source);
  cameras.Read("file", &job.cameras_file);
  cameras.RejectUnknownKeys();

  Section network = top.Child("network");
  network.Read("weights", &job.network_weights);
  network.Read("batch_size", &job.batch_size);
  network.Read("threads", &job.threads);
  network.Read("precision", &job.network_precision);
  std::string network_keypoints = ToString(job.network_keypoints);
  network.Read("keypoints", &network_keypoints);
  const std::optional<AnswerKeypoints> how = AnswerKeypointsNamed(network_keypoints);
  if (!how) {
    throw InputError(path, network.Name("keypoints"), AnswerKeypointsChoices(),
                     "'" + network_keypoints + "'");
  }
  job.network_keypoints = *how;
  network.RejectUnknownKeys();

  ReadRefineSection(top, path, &job);
  ReadEvidenceSection(top, path, &job);

  Section output = top.Child("output");
  output.Read("dir", &job.output_dir);
  output.Read("meshes", &job.meshes);
  output.Read("overlays", &job.overlays);
  output.Read("overlay_format", &job.overlay_format);
  output.Read("evaluate", &job.evaluate);
  output.Read("baseline", &job.baseline);
  output.RejectUnknownKeys();
  ReadFitSection(top, &job);
  ReadSequenceSection(top, &job);
  top.RejectUnknownKeys();

  job.input_path = Resolve(job.input_path, base);
  job.cameras_file = Resolve(job.cameras_file, base);
  job.detections = Resolve(job.detections, base);
  if (job.hand_model != "capsule")
    job.hand_model = Resolve(job.hand_model, base);  // built-in
  job.network_weights = Resolve(job.network_weights, base);
  job.output_dir = Resolve(job.output_dir, base);
  if (!IsFitInitKeyword(job.fit.init)) job.fit.init = Resolve(job.fit.init, base);
  if (std::optional<std::string>& model = job.fit.detector_keypoints;
      model && *model != "none" && *model != "mediapipe") {
    *model = Resolve(*model, base);
  }
  job.Check(path);
  return job;
}

}  // namespace handlabel
