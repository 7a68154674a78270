#pragma once
// `handlabel adapt`: teaches the network the user's own rig from the labels of the
// slow, careful method (a pseudo-label loop; docs/adapt.md). Stages, each kept on disk
// and marked done in <out>/stages/<name>.done, so that running the same command again
// continues where a killed run stopped:
//   detect    MediaPipe Hands on every frame, when the capture has no detections yet
//             (written into the capture, as `handlabel detect --capture` does)
//   fit       a fit-only job from the detections: <out>/fit/labels/
//   backgrounds  every camera's empty scene, the median of frames with the labelled
//             hand left out, for synthetic hands in the capture's look (only with
//             synth_share > 0): <out>/backgrounds/<camera>.png
//   train     fine-tunes the starting weights on the frames whose fit label agrees
//             with its detections (LabelSelectionRule) mixed with synthetic hands
//             over those backgrounds (synth_share), validating on a block of
//             held-out frames that never trains; the number of steps is planned once
//             from the measured time per step and the budget: <out>/train/ (plan.json)
//   export    the mean of the checkpoints of the last 30 % of the steps (low learning
//             rate), batch-norm statistics measured again on the capture's training
//             frames, float16: <out>/network.pt
//   heldout   network-only jobs with the starting and the adapted weights on the
//             held-out frames, compared with their fit labels, and the quality
//             checks' thresholds chosen on the adapted answers: <out>/heldout/
//   label     the capture labelled by network + quality checks (those thresholds)
//             + fallback fit: <out>/labels/, <out>/summary.json (the label job layout)
// <out>/model_card.json and .md say what the network learned from, how long, and the
// held-out numbers; <out>/progress.json the seconds each stage took.
// It lives in pipeline/ because it builds and runs label jobs (JobConfig, their
// quality thresholds) and a training config around the network and the fitter. The
// code: adapt.cc (options, output folder, the stages in order; detect, fit, label),
// adapt_training.cc (backgrounds, train, export), adapt_report.cc (held-out measurement, model
// card), adapt_thresholds.h (the thresholds' choice); adapt_run.h is their shared,
// internal state.

#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/capture_training_data.h"

namespace handlabel {

struct AdaptOptions {
  std::string capture_dir;  // a native capture (capture import, synth)
  std::string out_dir;
  // Wall-clock minutes for all stages together; the training gets what the others
  // leave (> 0).
  double budget_minutes = 60;
  int threads = 2;  // LibTorch threads and frames in parallel (>= 1)
  // Weights to start from; empty = the shipped models/poem_small_dexycb.pt.
  std::string weights;
  // Frames that never train and measure the result (a job's input.frames form);
  // empty = the last 16 frames when the capture has >= 40 (4 more before them are left
  // out, so that neighbours of held-out frames do not train), else none.
  std::string heldout;
  LabelSelectionRule selection;
  double learning_rate = 1e-4;
  // The label stage's quality-check thresholds are chosen on the adapted network's
  // held-out answers (pipeline/adapt_thresholds.h): an answer farther than this from
  // its fit label (mean keypoint distance, mm) counts as bad.
  double accept_mm = 10;
  // Share of training samples rendered in the capture's look (0..1): hands with exact
  // targets drawn with the capture's cameras over its own backgrounds (the backgrounds
  // stage); the rest are the capture's frames with their fit labels. 0 (the default):
  // capture frames only, no backgrounds stage. Off by default because on the real
  // development recording 0.5 left the network 0.9 mm farther from the fit labels and
  // passing fewer checks (docs/adapt.md); on a synthetic rig it brought it 1.2 mm
  // nearer the truth.
  double synth_share = 0;
  uint64_t seed = 1;  // training order, augmentation and torch seeds
  // Also write overlay pictures of the held-out and final labels.
  bool overlays = true;
  void Check(const std::string& source) const;
};

// The options that decide the result, as recorded in <out>/adapt.json (a later run
// into the same folder must agree with them).
nlohmann::json AdaptOptionsJson(const AdaptOptions& options);

struct AdaptSummary {
  std::string network_path;  // <out>/network.pt
  std::string labels_dir;    // <out>/labels
  nlohmann::json card;       // the model card's content
};

// Runs (or continues) the stages. Throws InputError naming the file and field when
// the folder holds another run (adapt.json), the selection rule keeps no training
// label, or a stage's input is unusable.
AdaptSummary RunAdaptation(const AdaptOptions& options, std::ostream* log);

}  // namespace handlabel
