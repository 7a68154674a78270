#include "pipeline/label_stage_factory.h"

#include "hand/detector_keypoints.h"

#include "capture/detections_frame_source.h"
#include "capture/dexycb_frame_source.h"
#include "capture/ho3d_frame_source.h"
#include "capture/native_frame_source.h"
#include "capture/oakink_frame_source.h"
#include "core/errors.h"
#include "pipeline/ceres_label_fitter.h"
#include "pipeline/detect_frame_source.h"
#include "pipeline/hand_model_source.h"
#include "pipeline/label_overlay.h"
#include "pipeline/network_stage.h"

namespace handlabel {

CeresLabelFitterOptions FitterOptions(const JobConfig& job) {
  const FitSettings& s = job.fit;
  CeresLabelFitterOptions o;
  o.use_masks = job.masks == MaskSource::kFiles;
  o.use_object_masks = job.object_masks;
  o.network_mask_sigma_px = job.network_mask_sigma_px;
  o.init = s.init;
  o.network_sigma_m = job.refine_network_sigma_mm / 1000;
  o.restart_px = job.refine_restart_px;
  o.fit.num_threads = 1;  // frames run in parallel
  if (s.keypoint_loss) {
    o.fit.keypoint_loss.type =
        RobustLossFromName(*s.keypoint_loss, job.source_file + " fit.keypoint_loss");
  }
  o.fit.keypoint_loss.scale = s.keypoint_loss_scale.value_or(o.fit.keypoint_loss.scale);
  o.fit.keypoint_sigma_px = s.keypoint_sigma_px.value_or(o.fit.keypoint_sigma_px);
  o.fit.silhouette_sigma_px = s.silhouette_sigma_px.value_or(o.fit.silhouette_sigma_px);
  o.fit.silhouette_rounds = s.silhouette_rounds.value_or(o.fit.silhouette_rounds);
  o.fit.mask_margin_max_px = s.mask_margin_px.value_or(o.fit.mask_margin_max_px);
  o.config.pose_pca_comps = s.pose_pca_comps.value_or(o.config.pose_pca_comps);
  o.config.use_joint_limits = s.joint_limits.value_or(o.config.use_joint_limits);
  o.config.optimise_shape = s.optimise_shape.value_or(o.config.optimise_shape);
  o.check_silhouettes = s.silhouette_check.value_or(o.check_silhouettes);
  if (s.unknown_occluders) {
    o.one_sided_without_object_masks = *s.unknown_occluders == "one_sided";
  }
  if (s.detector_keypoints) {
    if (auto model = DetectorKeypointModelOfSetting(
            *s.detector_keypoints, job.source_file, "fit.detector_keypoints")) {
      o.fit.detector_keypoints =
          std::make_shared<const DetectorKeypointModel>(std::move(*model));
    }
  }
  return o;
}

LabelStageSet BuiltLabelStages::Set() const {
  LabelStageSet set;
  set.source = source.get();
  set.predictor = predictor ? &*predictor : nullptr;
  set.fitter = fitter.get();
  set.overlays = overlays.get();
  set.hand_model_name = hand_model.name;
  set.side = hand_model.side;
  set.faces = hand_model.faces;
  set.find_keypoints_2d = find_keypoints_2d;
  set.start_video_track = start_video_track;
  set.write_detections = write_detections;
  return set;
}

namespace {

std::unique_ptr<FrameSource> BuildCaptureSource(const JobConfig& job,
                                                const std::optional<Rig>& cameras) {
  if (job.input_format == "native") {
    // 2D from the detector or an evidence.detections folder replaces the capture's:
    // its files are not read (a damaged one failed frames that did not use it).
    const bool other_2d = job.keypoints_from_detector || !job.detections.empty();
    return std::make_unique<NativeFrameSource>(
        job.input_path, cameras, other_2d ? "none" : job.keypoint_files, job.mask_files);
  }
  if (job.input_format == "dexycb") {
    return std::make_unique<DexYcbFrameSource>(job.input_path, cameras);
  }
  if (job.input_format == "ho3d") {
    return std::make_unique<Ho3dFrameSource>(job.input_path, cameras);
  }
  if (job.input_format == "oakink") {
    return std::make_unique<OakInkFrameSource>(job.input_path, cameras);
  }
  throw InputError(job.source_file, "input.format", "native | dexycb | ho3d | oakink",
                   "'" + job.input_format + "'");
}

}  // namespace

std::unique_ptr<FrameSource> BuildFrameSource(const JobConfig& job,
                                              std::shared_ptr<DetectionStore> detections,
                                              const DetectorFrameSource** detector) {
  std::optional<Rig> cameras;
  if (job.cameras_source == "file")
    cameras = ReadCamerasFile(job.cameras_file, job.source_file);
  std::unique_ptr<FrameSource> source = BuildCaptureSource(job, cameras);
  if (!job.detections.empty()) {
    source = std::make_unique<DetectionsFrameSource>(
        std::move(source), job.detections, job.source_file + ": evidence.detections");
  }
  if (job.keypoints_from_detector) {
    DetectCaptureOptions detect;
    detect.hands.model = job.detector_model;
    detect.hands.palm_tiles = ParsePalmTiles(job.detector_palm_tiles, job.source_file,
                                             "evidence.detector_palm_tiles");
    detect.video = job.detector_video;
    detect.palm_every = job.detector_palm_every;
    detect.multiview.max_hands = job.detector_max_hands;
    // A job that tracks detects only the frames that need it, one in video mode its
    // frames in order (label_job.h).
    const bool detect_on_load = job.detector_every == 1 && !job.detector_video;
    auto on_images = std::make_unique<DetectorFrameSource>(
        std::move(source), detect, std::move(detections), detect_on_load);
    if (detector) *detector = on_images.get();
    source = std::move(on_images);
  }
  // A dataset without 2D keypoints gives the network nothing to crop on and the fit
  // nothing to fit: the job must name its 2D.
  if (job.input_format != "native" && source->KeypointsSource().empty()) {
    throw InputError(job.source_file, "evidence.detections",
                     "a folder of 2D detections (<frame id>.json, the native detections "
                     "format that `handlabel detect` writes): input " +
                         job.input_format + " at " + job.input_path +
                         " has no 2D keypoints, and a job never runs without 2D",
                     "none");
  }
  return source;
}

BuiltLabelStages BuildLabelStages(const JobConfig& job,
                                  std::shared_ptr<PredictionMemo> memo) {
  BuiltLabelStages built;
  // The detector's answers (evidence.keypoints_2d: detector), written beside the
  // labels (the 2D a smoothing pass refits, docs/labeling-jobs.md) and drawn on the
  // overlays.
  std::shared_ptr<DetectionStore> detections;
  if (job.keypoints_from_detector) {
    detections = std::make_shared<DetectionStore>();
    built.write_detections = [detections](const std::string& output_dir,
                                          const FrameInput& frame) {
      detections->TakeAndWrite(output_dir, frame);
    };
  }
  const DetectorFrameSource* detector = nullptr;
  built.source = BuildFrameSource(job, detections, &detector);
  if (detector && job.detector_every > 1) {
    built.find_keypoints_2d = [detector](FrameInput* frame) { detector->Detect(frame); };
  }
  if (detector && job.detector_video) {
    built.start_video_track = [detector] {
      // The previous frame's answer, handed on from call to call (one caller at a
      // time); emptied first, so that a frame whose detection throws starts anew.
      auto previous = std::make_shared<std::optional<FrameHandResult>>();
      return std::function<void(FrameInput*)>([detector, previous](FrameInput* frame) {
        std::optional<FrameHandResult> last = std::move(*previous);
        previous->reset();
        *previous = detector->Detect(frame, last ? &*last : nullptr);
      });
    };
  }
  const HandSide side = built.source->side().value_or(HandSide::kRight);
  ResolvedHandModel hand = ResolveHandModel(job.hand_model, side);
  built.hand_model = std::move(hand.model);
  built.hand_model_note = std::move(hand.note);
  if (!job.network_weights.empty()) {
    built.predictor = LoadNetworkStage(job, std::move(memo));
    ReadAnswerKeypointsAs(job, built.hand_model, &*built.predictor);
  }
  if (job.masks == MaskSource::kNetwork &&
      !(built.predictor && built.predictor->predicts_masks)) {
    throw InputError(job.source_file, "evidence.masks",
                     "files or none (network needs network.weights with a mask head)",
                     built.predictor
                         ? "network, but " + job.network_weights + " has no mask head"
                         : "network, but no network.weights");
  }
  if (job.refine_mode != RefineMode::kOff || job.baseline) {
    built.fitter =
        std::make_unique<CeresLabelFitter>(built.hand_model, FitterOptions(job));
  }
  if (job.overlays) {
    built.overlays = std::make_unique<RasterOverlayWriter>(
        built.hand_model, job.overlay_format, detections);
  }
  return built;
}

}  // namespace handlabel
