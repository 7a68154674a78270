#pragma once
// Training POEM on a capture's own labels (docs/training.md, "Training on your own
// capture's labels"): which of the capture's frames train and which validate, and their
// labels, read from a label job's labels/ folder here in pipeline/ and handed to
// training/ (capture_training_samples.h) as plain arrays.

#include <memory>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "pipeline/train_config.h"
#include "training/capture_training_samples.h"

namespace handlabel {

struct CaptureTrainingInputs {
  std::string capture_dir;  // a native capture; its detections/ give the 2D keypoints
  std::string labels_dir;   // a folder of <frame>.json labels (a job's labels/)
  // The frames that train and those that validate, as a job's input.frames: "a:b"
  // (half-open range of positions in the capture's sorted frames), "id,id,..." or
  // "all". Empty train_frames: every frame that does not validate; empty val_frames:
  // none. No frame may do both.
  std::string train_frames;
  std::string val_frames;
};

struct CaptureTrainingData {
  std::unique_ptr<FrameSource> source;  // the capture
  std::vector<LabeledFrame> train;
  std::vector<LabeledFrame> validation;
};

// Throws InputError naming the flag (--train-frames, --val-frames) for a bad range or a
// frame in both, and the label file and field for a missing or unusable label.
CaptureTrainingData LoadCaptureTrainingData(const CaptureTrainingInputs& inputs,
                                            int num_vertices);

// A label file's keypoints_3d and vertices as a training target for `frame`. Throws
// InputError naming the file and field unless the label is of that frame, with 21
// finite keypoints and `num_vertices` finite vertices.
LabeledFrame ReadLabeledFrame(const std::string& path, const std::string& frame,
                              int num_vertices);

// The capture samples of a training config: its network's crop size, data.seed and
// augment.* (without rotation, which capture crops do not do). For validation: no
// augmentation, and every view cropped from its detections wherever they locate the
// hand, as inference crops it.
CaptureSampleOptions CaptureSampleOptionsFor(const TrainConfig& config, bool validation);

}  // namespace handlabel
