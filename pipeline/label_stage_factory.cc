#include "pipeline/label_stage_factory.h"

#include "core/errors.h"
#include "pipeline/ceres_label_fitter.h"
#include "capture/dexycb_frame_source.h"
#include "pipeline/hand_model_source.h"
#include "capture/ho3d_frame_source.h"
#include "pipeline/label_overlay.h"
#include "capture/native_frame_source.h"
#include "capture/oakink_frame_source.h"
#include "pipeline/network_stage.h"

namespace handlabel {

LabelStageSet BuiltLabelStages::Set() const {
  LabelStageSet set;
  set.source = source.get();
  set.predictor = predictor ? &*predictor : nullptr;
  set.fitter = fitter.get();
  set.overlays = overlays.get();
  set.hand_model_name = hand_model.name;
  set.side = hand_model.side;
  set.faces = hand_model.faces;
  return set;
}

std::unique_ptr<FrameSource> BuildFrameSource(const JobConfig& job) {
  std::optional<Rig> cameras;
  if (job.cameras_source == "file")
    cameras = ReadCamerasFile(job.cameras_file, job.source_file);
  if (job.input_format == "native") {
    return std::make_unique<NativeFrameSource>(job.input_path, cameras);
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

BuiltLabelStages BuildLabelStages(const JobConfig& job) {
  BuiltLabelStages built;
  built.source = BuildFrameSource(job);
  const HandSide side = built.source->side().value_or(HandSide::kRight);
  built.hand_model = ResolveHandModel(job.hand_model, side).model;
  if (!job.network_weights.empty()) {
    built.predictor = LoadNetworkStage(job.network_weights, job.batch_size, job.threads);
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
    HandFitOptions options;
    options.num_threads = 1;  // frames run in parallel
    built.fitter = std::make_unique<CeresLabelFitter>(
        built.hand_model, job.masks == MaskSource::kFiles, HandFitConfig(), options,
        job.network_mask_sigma_px);
  }
  if (job.overlays)
    built.overlays = std::make_unique<RasterOverlayWriter>(built.hand_model);
  return built;
}

}  // namespace handlabel
