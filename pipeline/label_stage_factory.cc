#include "pipeline/label_stage_factory.h"

#include "core/errors.h"

namespace handlabel {

LabelStageSet BuiltLabelStages::Set() const {
  LabelStageSet set;
  set.source = source.get();
  set.predictor = predictor.get();
  set.fitter = fitter.get();
  set.overlays = overlays.get();
  set.hand_model_name = hand_model.name;
  set.side = hand_model.side;
  set.faces = hand_model.faces;
  return set;
}

std::unique_ptr<FrameSource> BuildFrameSource(const JobConfig& job) {
  // The capture readers (native layout first) plug in here as they land.
  throw InputError(job.source_file, "input.format",
                   "a capture format with a reader in this build (none yet)",
                   "'" + job.input_format + "'");
}

BuiltLabelStages BuildLabelStages(const JobConfig& job) {
  BuiltLabelStages built;
  built.source = BuildFrameSource(job);
  return built;
}

}  // namespace handlabel
