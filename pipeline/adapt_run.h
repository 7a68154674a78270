#pragma once
// Internal to pipeline/ (scripts/check-header-deps): one `handlabel adapt` run's state
// and its stages, shared by adapt.cc (options, output folder, the stages in order;
// detect, fit and label), adapt_training.cc (train and export) and adapt_report.cc
// (held-out measurement, thresholds and the model card). pipeline/adapt.h has the
// command's interface.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "capture/frame_source.h"
#include "hand/hand_model.h"
#include "pipeline/adapt.h"
#include "pipeline/job_config.h"
#include "pipeline/label_summary.h"
#include "training/capture_training_samples.h"
#include "training/training_samples.h"

namespace handlabel {
namespace adapt {

// The run's state: its options, folders, frames and the seconds each stage took.
struct AdaptRun {
  AdaptOptions o;
  std::ostream* log = nullptr;
  std::filesystem::path out;
  std::vector<std::string> frames, train, heldout;
  int num_cameras = 0;
  nlohmann::json progress = nlohmann::json::object();  // stage -> seconds

  void Say(const std::string& line) const {
    if (log) *log << "handlabel adapt: " << line << std::endl;
  }
  std::string Path(const std::string& relative) const {
    return (out / relative).string();
  }
  double ElapsedSeconds() const {
    double s = 0;
    for (const auto& [stage, seconds] : progress.items()) s += seconds.get<double>();
    return s;
  }
};

// The file's JSON, or null when there is none.
nlohmann::json ReadIfExists(const std::string& path);

// A job over the capture's detections without masks (their 2D is the evidence).
JobConfig CaptureJob(const AdaptRun& run, const std::string& name,
                     const std::string& out);
// Runs (or continues) a job of the run.
LabelSummary RunJob(const AdaptRun& run, const JobConfig& job);
// The frames the fit labelled (it fails a frame whose detections do not pin the hand
// down, e.g. in fewer than two views): only they can teach or measure.
std::vector<std::string> WithFitLabel(const AdaptRun& run,
                                      const std::vector<std::string>& frames);

// The stages of adapt_training.cc and adapt_report.cc
// (pipeline/adapt.h says what each does and writes).
void BackgroundsStage(const AdaptRun& run);
void TrainStage(AdaptRun* run);
void ExportStage(const AdaptRun& run);
void HeldoutStage(const AdaptRun& run);

// The training plan checked on the way (plan.json): after every tenth of its steps
// (at least 100; NextPlanCheck gives the first check after `step`, 0 when none is left
// before the learning rate's decay at 70 %: only where the decay starts moves) the
// seconds per step measured since the previous check (or the timing run: 10 steps say
// little, with synthetic hands a step's cost varies by a third from batch to batch)
// replace the estimate, and Replan plans the steps again for what is left of the
// budget, `seconds` having passed since the previous check or the plan (whose
// seconds_before_training counts the timing run). Each check is kept in `checks`.
int64_t NextPlanCheck(const nlohmann::json& plan, int64_t step);
void Replan(int64_t step, double seconds_per_step, double seconds, nlohmann::json* plan);

// The label job file for new recordings of the rig (new_recordings.yaml): the adapted
// network with the chosen thresholds, the detector on 1 frame in
// kNewRecordingsDetectorEvery and the network's crops tracked in between.
constexpr int kNewRecordingsDetectorEvery = 10;
std::string JobForNewRecordings(const AdaptRun& run);

// Synthetic training samples in the capture's look (adapt_training.cc,
// capture/capture_look.h): hands rendered with `capture`'s cameras over the backgrounds
// stage's pictures, placed where the training `labels` put the hand, realistic look, half
// of them holding objects.
std::unique_ptr<SynthTrainingSamples> CaptureLookSynthSamples(
    const AdaptRun& run, const FrameSource& capture, const HandModel& hand,
    const std::vector<LabeledFrame>& labels, const TrainingSampleOptions& samples);

// The model card (model_card.json) and its Markdown (model_card.md).
nlohmann::json ModelCard(const AdaptRun& run);
std::string ModelCardMarkdown(const nlohmann::json& card);

}  // namespace adapt
}  // namespace handlabel
