#include "pipeline/capture_training_data.h"

#include <filesystem>
#include <set>

#include "capture/native_frame_source.h"
#include "core/errors.h"
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

std::vector<LabeledFrame> ReadLabels(const std::vector<std::string>& frames,
                                     const std::string& labels_dir, int num_vertices) {
  std::vector<LabeledFrame> labels;
  for (const std::string& id : frames) {
    const std::string stem = FrameFileStem(id, labels_dir);
    const std::string path =
        (std::filesystem::path(labels_dir) / (stem + ".json")).string();
    labels.push_back(ReadLabeledFrame(path, id, num_vertices));
  }
  return labels;
}

}  // namespace

LabeledFrame ReadLabeledFrame(const std::string& path, const std::string& frame,
                              int num_vertices) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "label file", "a label for frame '" + frame + "' (--labels)",
                     "no such file");
  }
  const LabelRecord label = ReadLabelFile(path);
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

CaptureTrainingData LoadCaptureTrainingData(const CaptureTrainingInputs& in,
                                            int num_vertices) {
  CaptureTrainingData data;
  data.source = std::make_unique<NativeFrameSource>(in.capture_dir);
  std::vector<std::string> train, validation;
  SplitFrames(data.source->FrameIds(), in, &train, &validation);
  data.train = ReadLabels(train, in.labels_dir, num_vertices);
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
