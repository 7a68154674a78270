// The job's identity and frames (pipeline/label_job.h): the hash of everything that can
// change a label, and which frames of the capture the job labels.

#include <set>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "formats/sha256.h"
#include "pipeline/label_job.h"
#include "pipeline/label_record.h"

namespace handlabel {
namespace {

template <typename T>
nlohmann::json Optional(const std::optional<T>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

nlohmann::json FitSettingsJson(const FitSettings& f) {
  nlohmann::json j = {f.init,
                      Optional(f.keypoint_loss),
                      Optional(f.keypoint_loss_scale),
                      Optional(f.keypoint_sigma_px),
                      Optional(f.silhouette_sigma_px),
                      Optional(f.silhouette_rounds),
                      Optional(f.pose_pca_comps),
                      Optional(f.joint_limits),
                      Optional(f.optimise_shape)};
  // Added later: only when set, so the hash of older fit settings stays.
  if (f.silhouette_check || f.unknown_occluders) {
    j.push_back({Optional(f.silhouette_check), Optional(f.unknown_occluders)});
  }
  if (f.mask_margin_px) j.push_back({{"mask_margin_px", *f.mask_margin_px}});
  if (f.detector_keypoints) {
    j.push_back({{"detector_keypoints", *f.detector_keypoints}});
  }
  return j;
}

}  // namespace

std::string JobHash(const JobConfig& job, const std::string& weights_sha256) {
  const QualityThresholds& q = job.quality;
  nlohmann::json j = {
      {"label_format", kLabelFormatVersion},
      {"input", {job.input_format, job.input_path, job.frames}},
      {"cameras", {job.cameras_source, job.cameras_file}},
      {"hand_model", job.hand_model},
      {"weights_sha256", weights_sha256},
      {"refine",
       {ToString(job.refine_mode), q.max_reprojection_px, q.max_view_disagreement_mm,
        q.min_confidence, q.min_views, q.min_hand_span_m, q.max_hand_span_m}},
      {"evidence", {static_cast<int>(job.keypoints), static_cast<int>(job.masks)}},
      {"seed", job.seed}};
  // Fields added later enter only when set, so older jobs keep their hash (and their
  // output folders resume).
  nlohmann::json extra = nlohmann::json::object();
  if (job.max_frames > 0) extra["max_frames"] = job.max_frames;
  if (job.keypoint_files != "auto" || job.mask_files != "auto" ||
      !job.ignore_views.empty()) {
    extra["evidence_files"] = {job.keypoint_files, job.mask_files, job.ignore_views};
  }
  if (!job.fit.IsDefault()) extra["fit"] = FitSettingsJson(job.fit);
  if (!job.object_masks) extra["object_masks"] = "none";
  if (!job.detections.empty()) extra["detections"] = job.detections;
  if (job.keypoints_from_detector) extra["detector"] = job.detector_model;
  if (job.keypoints_from_detector && job.detector_palm_tiles != "auto") {
    extra["detector_palm_tiles"] = job.detector_palm_tiles;
  }
  if (job.detector_every != 1) extra["detector_every"] = job.detector_every;
  if (job.detector_video) extra["detector_video"] = job.detector_palm_every;
  if (job.detector_max_hands != 1) extra["detector_max_hands"] = job.detector_max_hands;
  // The requested arithmetic; what "auto" chose on each machine is in every label's
  // provenance (model name).
  if (!weights_sha256.empty() && job.network_precision != "fp32") {
    extra["network_precision"] = job.network_precision;
  }
  // Labels made before the reading was chosen used the joints.
  if (!weights_sha256.empty() && job.network_keypoints != AnswerKeypoints::kJoints) {
    extra["network_keypoints"] = ToString(job.network_keypoints);
  }
  // Refinement against file 2D changed (issue 43): the network's answer is a loose start
  // with a restart from the views, so jobs that refine it against files hash anew.
  if (!weights_sha256.empty() && job.keypoints != KeypointSource::kNetwork &&
      job.refine_mode != RefineMode::kOff) {
    extra["refine_against_files"] = {job.refine_network_sigma_mm, job.refine_restart_px};
  }
  // The network's answer judged against the file 2D too (issue 43).
  if (!weights_sha256.empty() && job.keypoints != KeypointSource::kNetwork) {
    extra["detector_agreement"] = q.max_detector_rms_px;
  }
  if (!extra.empty()) j["added"] = extra;
  return Sha256Hex(j.dump());
}

std::vector<std::string> SelectFrames(const std::vector<std::string>& all_frames,
                                      const std::string& spec, const std::string& source,
                                      const std::string& field) {
  if (spec == "all" || spec.empty()) return all_frames;
  const size_t colon = spec.find(':');
  if (colon != std::string::npos) {
    size_t begin = 0, end = all_frames.size();
    try {
      if (colon > 0) begin = std::stoul(spec.substr(0, colon));
      if (colon + 1 < spec.size()) end = std::stoul(spec.substr(colon + 1));
    } catch (const std::exception&) {
      throw InputError(source, field, "'all', 'a:b' or 'id,id,...'", "'" + spec + "'");
    }
    if (begin > end || end > all_frames.size()) {
      throw InputError(
          source, field,
          "a range within the capture's " + std::to_string(all_frames.size()) + " frames",
          "'" + spec + "'");
    }
    return {all_frames.begin() + begin, all_frames.begin() + end};
  }
  const std::set<std::string> known(all_frames.begin(), all_frames.end());
  std::set<std::string> chosen;
  size_t start = 0;
  while (start <= spec.size()) {
    size_t comma = spec.find(',', start);
    if (comma == std::string::npos) comma = spec.size();
    std::string id = spec.substr(start, comma - start);
    id.erase(0, id.find_first_not_of(' '));
    id.erase(id.find_last_not_of(' ') + 1);
    if (!id.empty()) {
      if (!known.count(id)) {
        throw InputError(source, field, "frame ids of the capture", "'" + id + "'");
      }
      if (!chosen.insert(id).second) {
        throw InputError(source, field, "each frame id once",
                         "'" + id + "' listed twice");
      }
    }
    start = comma + 1;
  }
  std::vector<std::string> frames;
  for (const std::string& f : all_frames) {
    if (chosen.count(f)) frames.push_back(f);
  }
  return frames;
}

std::vector<std::string> JobFrames(const JobConfig& job, const FrameSource& source) {
  const std::vector<std::string> all = source.FrameIds();
  std::set<std::string> seen;
  for (const std::string& id : all) {  // a frame listed twice would be labelled twice
    if (!seen.insert(id).second) {
      throw InputError(source.Describe(), "frames", "each frame id once",
                       "'" + id + "' listed twice");
    }
  }
  std::vector<std::string> frames = SelectFrames(all, job.frames, job.source_file);
  if (job.max_frames > 0 && static_cast<int>(frames.size()) > job.max_frames) {
    frames.resize(job.max_frames);
  }
  return frames;
}

}  // namespace handlabel
