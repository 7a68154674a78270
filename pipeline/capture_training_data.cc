#include "pipeline/capture_training_data.h"

#include <filesystem>
#include <set>

#include "capture/native_frame_source.h"
#include "core/errors.h"
#include "core/option_checks.h"
#include "core/text.h"
#include "pipeline/label_job.h"
#include "pipeline/label_record.h"

namespace handlabel {
namespace {

constexpr char kCommandLine[] = "command line";

// The frames of each role; the training frames default to those not validating.
void SplitFrames(const std::vector<std::string>& all, const CaptureTrainingInputs& in,
                 std::vector<std::string>* train, std::vector<std::string>* validation) {
  if (!in.val_frames.empty()) {
    *validation = SelectFrames(all, in.val_frames, kCommandLine, "--val-frames");
  }
  const std::set<std::string> validating(validation->begin(), validation->end());
  if (in.train_frames.empty()) {
    for (const std::string& id : all) {
      if (!validating.count(id)) train->push_back(id);
    }
  } else {
    *train = SelectFrames(all, in.train_frames, kCommandLine, "--train-frames");
  }
  for (const std::string& id : *train) {
    if (validating.count(id)) {
      throw InputError(kCommandLine, "--val-frames", "frames that do not also train",
                       "frame '" + id + "' in both --train-frames and --val-frames");
    }
  }
  if (train->empty()) {
    throw InputError(kCommandLine, "--train-frames", "at least one frame", "none");
  }
}

std::string LabelPathOf(const std::string& labels_dir, const std::string& frame) {
  const std::string stem = FrameFileStem(frame, labels_dir);
  return (std::filesystem::path(labels_dir) / (stem + ".json")).string();
}

LabelRecord ReadFrameLabel(const std::string& path, const std::string& frame) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "label file", "a label for frame '" + frame + "' (--labels)",
                     "no such file");
  }
  return ReadLabelFile(path);
}

// The label's keypoints and vertices as a target, checked (ReadLabeledFrame's errors).
LabeledFrame ToLabeledFrame(const LabelRecord& label, const std::string& path,
                            const std::string& frame, int num_vertices) {
  if (label.frame != frame) {
    throw InputError(path, "frame", "'" + frame + "'", "'" + label.frame + "'");
  }
  if (!label.mesh.keypoints.allFinite()) {
    throw InputError(path, "keypoints_3d", "21 finite keypoints", "null or NaN values");
  }
  if (label.mesh.vertices.rows() != num_vertices || !label.mesh.vertices.allFinite()) {
    throw InputError(
        path, "vertices",
        std::to_string(num_vertices) + " finite vertices (the network's mesh)",
        std::to_string(label.mesh.vertices.rows()) +
            (label.mesh.vertices.allFinite() ? "" : ", not all finite"));
  }
  return {frame, label.mesh.keypoints, label.mesh.vertices};
}

std::vector<LabeledFrame> ReadLabels(const std::vector<std::string>& frames,
                                     const std::string& labels_dir, int num_vertices) {
  std::vector<LabeledFrame> labels;
  for (const std::string& id : frames) {
    const std::string path = LabelPathOf(labels_dir, id);
    labels.push_back(ToLabeledFrame(ReadFrameLabel(path, id), path, id, num_vertices));
  }
  return labels;
}

// The training frames' labels that the rule keeps; `selection` gets every frame.
std::vector<LabeledFrame> SelectLabels(const std::vector<std::string>& frames,
                                       const std::string& labels_dir, int num_vertices,
                                       const LabelSelectionRule& rule,
                                       std::vector<LabelSelection>* selection) {
  std::vector<LabeledFrame> kept;
  for (const std::string& id : frames) {
    const std::string path = LabelPathOf(labels_dir, id);
    const LabelRecord label = ReadFrameLabel(path, id);
    LabeledFrame target = ToLabeledFrame(label, path, id, num_vertices);
    selection->push_back(SelectTrainingLabel(label, rule));
    if (selection->back().kept) kept.push_back(std::move(target));
  }
  if (kept.empty()) {
    throw InputError(kCommandLine, "--label-min-views / --label-max-rms-px",
                     "a rule that keeps at least one training label",
                     "none of " + std::to_string(frames.size()) + " kept");
  }
  return kept;
}

}  // namespace

void LabelSelectionRule::Check(const std::string& source) const {
  RequireAtLeast(source, "--label-min-views", min_views, 2);
  RequireGreater(source, "--label-max-rms-px", max_view_rms_px, 0);
}

LabelSelection SelectTrainingLabel(const LabelRecord& label,
                                   const LabelSelectionRule& rule) {
  LabelSelection s{label.frame, false, ""};
  if (label.path == LabelPath::kNetwork) {
    s.kept = label.quality.Passed();
    s.why = s.kept ? "network answer, every check passed"
                   : "network answer, failed: " + label.quality.FailedNames();
    return s;
  }
  int good = 0, measured = 0;
  if (label.fit.is_object() && label.fit.contains("view_rms_px")) {
    for (const auto& rms : label.fit["view_rms_px"]) {
      if (!rms.is_number()) continue;
      ++measured;
      good += rms.get<double>() <= rule.max_view_rms_px;
    }
  }
  s.kept = good >= rule.min_views;
  s.why = std::to_string(good) + " of " + std::to_string(measured) + " views within " +
          FormatNumber(rule.max_view_rms_px) + " px";
  return s;
}

nlohmann::json LabelSelectionJson(const LabelSelectionRule& rule,
                                  const std::vector<LabelSelection>& selection) {
  nlohmann::json frames = nlohmann::json::array();
  int kept = 0;
  for (const LabelSelection& s : selection) {
    kept += s.kept;
    frames.push_back({{"frame", s.frame}, {"kept", s.kept}, {"why", s.why}});
  }
  return {{"rule",
           "a network answer that passed every check, or a fit with at least min_views "
           "views whose fit.view_rms_px <= max_view_rms_px"},
          {"min_views", rule.min_views},
          {"max_view_rms_px", rule.max_view_rms_px},
          {"kept", kept},
          {"training_frames", selection.size()},
          {"frames", frames}};
}

LabeledFrame ReadLabeledFrame(const std::string& path, const std::string& frame,
                              int num_vertices) {
  return ToLabeledFrame(ReadFrameLabel(path, frame), path, frame, num_vertices);
}

CaptureTrainingData LoadCaptureTrainingData(const CaptureTrainingInputs& in,
                                            int num_vertices) {
  CaptureTrainingData data;
  data.source = std::make_unique<NativeFrameSource>(in.capture_dir);
  std::vector<std::string> train, validation;
  SplitFrames(data.source->FrameIds(), in, &train, &validation);
  in.selection.Check(kCommandLine);
  data.train =
      SelectLabels(train, in.labels_dir, num_vertices, in.selection, &data.selection);
  data.validation = ReadLabels(validation, in.labels_dir, num_vertices);
  return data;
}

CaptureSampleOptions CaptureSampleOptionsFor(const TrainConfig& config, bool validation) {
  CaptureSampleOptions o;
  o.crop_size = config.network.crop_size;
  o.seed = config.synth.seed;
  o.augment = config.samples.augment;
  o.augment.rotation_probability = 0;
  if (validation) {
    o.augment.enabled = false;
    o.detection_crop_probability = 1;
  }
  return o;
}

}  // namespace handlabel
