#pragma once
// Training POEM on a capture's own labels (docs/training.md, "Training on your own
// capture's labels"): which of the capture's frames train and which validate, and their
// labels, read from a label job's labels/ folder here in pipeline/ and handed to
// training/ (capture_training_samples.h) as plain arrays. It is in pipeline/ because it
// reads a training config (TrainConfig -> CaptureSampleOptions) and the label job's own
// output format (pipeline/label_record.h), which training/ may not include.

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capture/frame_source.h"
#include "pipeline/label_record.h"
#include "pipeline/train_config.h"
#include "training/capture_training_samples.h"

namespace handlabel {

// Which labels of the training frames may teach the network (the held-out frames are
// judged whatever their labels score). A label trains when it is a network answer that
// passed every quality check, or a fit whose report (`fit.view_rms_px`, the RMS pixel
// distance of the fitted keypoints to the 2D it was fitted to, per view) shows at least
// `min_views` views within `max_view_rms_px`: a fit that agrees with the evidence in
// enough views to pin the hand down in 3D. Labels from a fit with fewer such views
// are where the detector was unsure, and teaching the network those would teach it
// the fit's guesses.
struct LabelSelectionRule {
  int min_views = 3;            // --label-min-views, >= 2 (one view does not pin depth)
  double max_view_rms_px = 10;  // --label-max-rms-px, > 0
  void Check(const std::string& source) const;
};

// One training frame's label and whether the rule kept it (`why`: the rule's reading).
struct LabelSelection {
  std::string frame;
  bool kept = false;
  std::string why;
};

struct CaptureTrainingInputs {
  std::string capture_dir;  // a native capture; its detections/ give the 2D keypoints
  std::string labels_dir;   // a folder of <frame>.json labels (a job's labels/)
  // The frames that train and those that validate, as a job's input.frames: "a:b"
  // (half-open range of positions in the capture's sorted frames), "id,id,..." or
  // "all". Empty train_frames: every frame that does not validate; empty val_frames:
  // none. No frame may do both.
  std::string train_frames;
  std::string val_frames;
  LabelSelectionRule selection;
};

struct CaptureTrainingData {
  std::unique_ptr<FrameSource> source;  // the capture
  std::vector<LabeledFrame> train;      // the training frames whose labels were kept
  std::vector<LabeledFrame> validation;
  std::vector<LabelSelection> selection;  // every training frame, kept or not
};

// Whether `label` may train under `rule`, and why.
LabelSelection SelectTrainingLabel(const LabelRecord& label,
                                   const LabelSelectionRule& rule);

// The selection as JSON: the rule, the counts and every frame's reading, written into
// the training run's folder (capture_labels.json) so a run says what it learned from.
nlohmann::json LabelSelectionJson(const LabelSelectionRule& rule,
                                  const std::vector<LabelSelection>& selection);

// Throws InputError naming the flag (--train-frames, --val-frames) for a bad range or a
// frame in both, or when the rule keeps no training label, and the label file and
// field for a missing or unusable label.
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
