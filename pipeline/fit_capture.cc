#include "pipeline/fit_capture.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/hand_anatomy.h"
#include "core/metrics.h"
#include "fitting/silhouette_render.h"
#include "core/atomic_file.h"
#include "capture/capture_reader.h"
#include "pipeline/fit_overlay.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

template <typename Vec>
json Array(const Vec& v) {
  json a = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

json PointsJson(const Points3d& p) {
  json a = json::array();
  for (Eigen::Index i = 0; i < p.rows(); ++i) a.push_back({p(i, 0), p(i, 1), p(i, 2)});
  return a;
}

json Finite(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

Eigen::VectorXd VectorFromJson(const json& j, const std::string& source,
                               const std::string& field, int size) {
  if (!j.is_array() || (size >= 0 && static_cast<int>(j.size()) != size)) {
    throw InputError(source, field,
                     size >= 0 ? "an array of " + std::to_string(size) + " numbers"
                               : "an array of numbers");
  }
  Eigen::VectorXd v(j.size());
  for (size_t i = 0; i < j.size(); ++i) {
    if (!j[i].is_number()) throw InputError(source, field, "numbers");
    v[i] = j[i].get<double>();
  }
  return v;
}

HandParams ParamsFromJson(const json& file, const std::string& source) {
  const json& j =
      file.contains("params") && file["params"].is_object() ? file["params"] : file;
  for (const char* key : {"global_orient", "hand_pose", "betas", "transl"}) {
    if (!j.contains(key))
      throw InputError(source, key,
                       "MANO parameters (global_orient, "
                       "hand_pose, betas, transl)");
  }
  HandParams p;
  p.global_orient = VectorFromJson(j["global_orient"], source, "global_orient", 3);
  p.hand_pose = VectorFromJson(j["hand_pose"], source, "hand_pose", kNumPoseParams);
  p.betas = VectorFromJson(j["betas"], source, "betas", -1);
  p.transl = VectorFromJson(j["transl"], source, "transl", 3);
  return p;
}

HandParams ReadInitFile(const std::string& dir, const std::string& frame) {
  for (const std::string& rel :
       {frame + ".json", "frames/" + frame + ".json", "labels/" + frame + ".json"}) {
    const fs::path path = fs::path(dir) / rel;
    if (!fs::exists(path)) continue;
    std::ifstream in(path);
    json j;
    try {
      j = json::parse(in);
    } catch (const json::exception& e) {
      throw InputError(path.string(), "(file)", "JSON", e.what());
    }
    return ParamsFromJson(j, path.string());
  }
  throw InputError("--init " + dir, frame + ".json",
                   "a per-frame parameter file (<frame>.json, frames/ or labels/)");
}

KeypointView ToKeypointView(const ViewKeypoints& v, const RigCamera& camera,
                            bool exact_projections) {
  KeypointView out;
  out.camera = camera;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const double u = v.keypoints.uv_px(k, 0), w = v.keypoints.uv_px(k, 1);
    const bool finite = std::isfinite(u) && std::isfinite(w);
    out.keypoints.uv_px(k, 0) = finite ? u : 0.0;
    out.keypoints.uv_px(k, 1) = finite ? w : 0.0;
    const double confidence = exact_projections ? 1.0 : v.keypoints.confidence[k];
    out.keypoints.confidence[k] = finite ? std::max(0.0, confidence) : 0.0;
  }
  return out;
}

struct FrameOutcome {
  bool has_truth = false;
  HandFrameMetrics metrics;
  Eigen::VectorXd keypoint_errors;
  double seconds = 0.0;
  bool converged = false;
  double limit_violation_deg = 0.0;
  HandParams params;
};

}  // namespace

void FitCaptureOptions::Check() const {
  if (capture_dir.empty())
    throw InputError("command line", "--capture", "a capture folder");
  if (out_dir.empty()) throw InputError("command line", "--out", "an output folder");
  if (max_frames < 0) {
    throw InputError("command line", "--max-frames", ">= 0", std::to_string(max_frames));
  }
  if (evidence != "auto" && evidence != "detections" && evidence != "keypoints") {
    throw InputError("command line", "--evidence", "auto, detections or keypoints",
                     evidence);
  }
  if (masks != "auto" && masks != "detections" && masks != "truth" && masks != "none") {
    throw InputError("command line", "--masks", "auto, detections, truth or none", masks);
  }
  if (init.empty()) {
    throw InputError("command line", "--init", "triangulate, gt, previous or a folder");
  }
  if (num_threads < 0) {
    throw InputError("command line", "--threads", ">= 0", std::to_string(num_threads));
  }
  config.Check();
  fit.Check();
}

FitCaptureSummary FitCapture(const FitCaptureOptions& options, const HandModel& model) {
  options.Check();
  const CaptureReader capture(options.capture_dir);
  // Which frames.
  std::vector<int> frames;
  if (options.frames.empty()) {
    for (int f = 0; f < capture.num_frames(); ++f) frames.push_back(f);
  } else {
    for (const std::string& id : options.frames) {
      const int f = capture.FrameIndex(id);
      if (f < 0) throw InputError("--frames", id, "a frame id of the capture");
      frames.push_back(f);
    }
  }
  if (options.max_frames > 0 && static_cast<int>(frames.size()) > options.max_frames) {
    frames.resize(options.max_frames);
  }
  // Which evidence.
  const bool use_detections =
      options.evidence == "detections" ||
      (options.evidence == "auto" && capture.Has(kFileDetections));
  if (use_detections && !capture.Has(kFileDetections)) {
    throw InputError(options.capture_dir, "detections", "a capture with detections");
  }
  if (!use_detections && !capture.Has(kFileKeypoints)) {
    throw InputError(options.capture_dir, "keypoints", "a capture with 2D keypoints");
  }
  std::string mask_kind;
  if (options.masks == "detections" ||
      (options.masks == "auto" && capture.Has(kFileDetectionMask))) {
    mask_kind = kFileDetectionMask;
  } else if (options.masks == "truth" ||
             (options.masks == "auto" && capture.Has(kFileMask))) {
    mask_kind = kFileMask;
  }
  if (!mask_kind.empty() && !capture.Has(mask_kind)) {
    throw InputError(options.capture_dir, mask_kind, "a capture with these masks");
  }
  const bool has_truth = capture.Has(kFileGroundTruth);
  if (options.init == "gt" && !has_truth) {
    throw InputError("--init", "gt", "a capture with ground truth");
  }

  std::vector<char> ignored(capture.rig().size(), 0);
  for (const std::string& name : options.ignore_views) {
    const int c = capture.rig().IndexOf(name);
    if (c < 0) throw InputError("--ignore-views", name, "a camera name of the capture");
    ignored[c] = 1;
  }
  const CeresHandFitter fitter(model, options.config, options.fit);
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  const HandLimits limits = DefaultHandLimits();
  std::vector<PixelRays> rays;
  if (!mask_kind.empty()) {
    for (size_t c = 0; c < capture.rig().size(); ++c)
      rays.emplace_back(capture.rig()[c].camera);
  }
  fs::create_directories(fs::path(options.out_dir) / "frames");

  std::vector<FrameOutcome> outcomes(frames.size());
  auto fit_frame = [&](size_t i, const HandParams* previous) {
    const int f = frames[i];
    const std::string& id = capture.frame_id(f);
    const std::vector<ViewKeypoints> views2d =
        use_detections ? capture.ReadDetections(f) : capture.ReadKeypoints(f);
    HandFitInput input;
    for (size_t c = 0; c < views2d.size(); ++c) {
      input.views.push_back(
          ToKeypointView(views2d[c], capture.rig()[c], !use_detections));
    }
    if (!mask_kind.empty()) {
      for (size_t c = 0; c < capture.rig().size(); ++c) {
        if (ignored[c]) {
          input.masks.emplace_back();
          continue;
        }
        input.masks.push_back(MaskFromImage(
            mask_kind == kFileMask ? capture.ReadMask(f, static_cast<int>(c))
                                   : capture.ReadDetectionMask(f, static_cast<int>(c))));
      }
      input.pixel_rays = &rays;
    }
    HandGroundTruth truth;
    if (has_truth) truth = capture.ReadGroundTruth(f);
    HandParams init;
    if (options.init == "triangulate") {
      init = fitter.InitFromViews(input.views);
    } else if (options.init == "gt") {
      init = truth.params;
    } else if (options.init == "previous") {
      init = previous != nullptr ? *previous : fitter.InitFromViews(input.views);
      if (previous != nullptr) input.previous = *previous;
    } else {
      init = ReadInitFile(options.init, id);
    }
    const HandFitResult result = fitter.Fit(input, init);
    if (i == 0 && !options.overlay_png.empty()) {
      std::vector<ImageU8> images;
      std::vector<PixelRays> overlay_rays;
      for (size_t c = 0; c < capture.rig().size(); ++c) {
        images.push_back(capture.ReadImage(f, static_cast<int>(c)));
        if (rays.empty()) overlay_rays.emplace_back(capture.rig()[c].camera);
      }
      WritePng(options.overlay_png,
               MakeFitOverlay(images, input.views, rays.empty() ? overlay_rays : rays,
                              result.vertices, model.faces, result.keypoints),
               PngWriteOptions{9});
    }

    FrameOutcome& out = outcomes[i];
    out.params = result.params;
    out.seconds = result.seconds;
    out.converged = result.converged;
    HandPoseVector angles;
    HandAnatomicalAngles(anatomy, result.params.hand_pose.data(), angles.data());
    out.limit_violation_deg = MaxLimitViolationDeg(limits, angles);
    json j;
    j["frame"] = id;
    j["hand_model"] = model.name;
    j["global_orient"] = Array(result.params.global_orient);
    j["hand_pose"] = Array(result.params.hand_pose);
    j["betas"] = Array(result.params.betas);
    j["transl"] = Array(result.params.transl);
    j["keypoints"] = PointsJson(result.keypoints);
    j["vertices"] = PointsJson(result.vertices);
    j["term_costs"] = result.term_costs;
    json rms = json::array(), iou = json::array();
    for (double x : result.view_rms_px) rms.push_back(Finite(x));
    for (double x : result.view_iou) iou.push_back(Finite(x));
    j["view_reprojection_rms_px"] = rms;
    j["view_silhouette_iou"] = iou;
    j["iterations"] = result.iterations;
    j["seconds"] = result.seconds;
    j["converged"] = result.converged;
    j["solver_message"] = result.message;
    j["max_limit_violation_deg"] = out.limit_violation_deg;
    if (has_truth) {
      out.has_truth = true;
      const bool same_mesh = truth.vertices.rows() == result.vertices.rows();
      out.metrics = EvaluateHandFrame(result.keypoints, truth.keypoints,
                                      same_mesh ? result.vertices : Points3d(),
                                      same_mesh ? truth.vertices : Points3d());
      out.keypoint_errors = PointErrors(result.keypoints, truth.keypoints);
      j["errors_mm"] = {{"mpjpe", 1000 * out.metrics.mpjpe},
                        {"pa_mpjpe", 1000 * out.metrics.pa_mpjpe},
                        {"rr_mpjpe", 1000 * out.metrics.rr_mpjpe}};
      if (same_mesh) {
        j["errors_mm"]["mpvpe"] = 1000 * out.metrics.mpvpe;
        j["errors_mm"]["pa_mpvpe"] = 1000 * out.metrics.pa_mpvpe;
        j["errors_mm"]["rr_mpvpe"] = 1000 * out.metrics.rr_mpvpe;
      }
    }
    WriteFileAtomically((fs::path(options.out_dir) / "frames" / (id + ".json")).string(),
                        j.dump(1) + "\n");
  };

  if (options.init == "previous") {
    for (size_t i = 0; i < frames.size(); ++i) {
      fit_frame(i, i > 0 ? &outcomes[i - 1].params : nullptr);
    }
  } else {
    const int threads = options.num_threads > 0
                            ? options.num_threads
                            : static_cast<int>(tbb::this_task_arena::max_concurrency());
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    tbb::parallel_for(size_t(0), frames.size(), [&](size_t i) { fit_frame(i, nullptr); });
  }

  // Summary.
  FitCaptureSummary s;
  s.frames = static_cast<int>(frames.size());
  s.has_ground_truth = has_truth;
  std::vector<double> seconds;
  Eigen::MatrixXd errors(frames.size(), kNumHandKeypoints);
  for (size_t i = 0; i < outcomes.size(); ++i) {
    const FrameOutcome& o = outcomes[i];
    s.converged += o.converged;
    seconds.push_back(o.seconds);
    s.max_limit_violation_deg =
        std::max(s.max_limit_violation_deg, o.limit_violation_deg);
    if (o.has_truth) {
      s.mpjpe += o.metrics.mpjpe;
      s.mpvpe += o.metrics.mpvpe;
      s.pa_mpjpe += o.metrics.pa_mpjpe;
      s.pa_mpvpe += o.metrics.pa_mpvpe;
      s.rr_mpjpe += o.metrics.rr_mpjpe;
      s.rr_mpvpe += o.metrics.rr_mpvpe;
      errors.row(i) = o.keypoint_errors.transpose();
    }
  }
  const double n = std::max<size_t>(1, frames.size());
  for (double* x :
       {&s.mpjpe, &s.mpvpe, &s.pa_mpjpe, &s.pa_mpvpe, &s.rr_mpjpe, &s.rr_mpvpe}) {
    *x /= n;
  }
  for (double x : seconds) s.mean_seconds += x / n;
  std::vector<double> sorted = seconds;
  std::sort(sorted.begin(), sorted.end());
  json j;
  j["capture"] = options.capture_dir;
  j["hand_model"] = model.name;
  j["frames"] = s.frames;
  j["converged"] = s.converged;
  j["evidence"] = use_detections ? "detections" : "keypoints";
  j["masks"] = mask_kind.empty() ? "none" : mask_kind;
  j["init"] = options.init;
  j["ignored_views"] = options.ignore_views;
  j["robust_loss"] = RobustLossName(options.fit.keypoint_loss.type);
  j["seconds_per_frame"] = {{"mean", s.mean_seconds},
                            {"median", sorted.empty() ? 0.0 : sorted[sorted.size() / 2]},
                            {"max", sorted.empty() ? 0.0 : sorted.back()}};
  j["max_limit_violation_deg"] = s.max_limit_violation_deg;
  if (has_truth && !frames.empty()) {
    const PckCurve pck = ComputePck(errors);
    s.auc_joints = pck.auc;
    j["errors_mm"] = {{"mpjpe", 1000 * s.mpjpe},       {"pa_mpjpe", 1000 * s.pa_mpjpe},
                      {"rr_mpjpe", 1000 * s.rr_mpjpe}, {"mpvpe", 1000 * s.mpvpe},
                      {"pa_mpvpe", 1000 * s.pa_mpvpe}, {"rr_mpvpe", 1000 * s.rr_mpvpe}};
    j["pck_joints"] = {
        {"thresholds_mm", json::array()}, {"pck", pck.pck}, {"auc", pck.auc}};
    for (double t : pck.thresholds) j["pck_joints"]["thresholds_mm"].push_back(1000 * t);
  }
  s.summary_path = (fs::path(options.out_dir) / "summary.json").string();
  WriteFileAtomically(s.summary_path, j.dump(1) + "\n");
  return s;
}

}  // namespace handlabel
