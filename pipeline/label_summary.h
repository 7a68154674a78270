#pragma once
// What a labeling run (one shard) or a merge (the whole job) reports: how many frames
// were labelled and by which path, which failed and why, the time spent, and, when the
// capture has ground truth, the errors per group of frames.
//
// Metric groups (keys "<group>/<metric>" in FrameRecord::metrics, metrics as in
// frame_metrics.h; the motion metrics from the records' keypoints over consecutive
// frames, each group's over the triples of consecutive frames it has):
//   network, refined, fallback_fit  the labels, grouped by the path that produced them
//   labels                          every label
//   network_raw                     the network's answer on every frame it ran on,
//                                   before quality checks
//   fit_only                        the fit-only baseline on every frame
//   (output.baseline)

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/frame_log.h"

namespace handlabel {

struct MetricMean {
  double sum = 0;
  int count = 0;
  double Mean() const { return count > 0 ? sum / count : 0.0; }
};

struct LabelSummary {
  int frames = 0;                      // frames of the job (merge) or of the shard (run)
  int ok = 0;                          // labelled (now or in an earlier run)
  int failed = 0;                      // finished with an error
  int missing = 0;                     // never attempted (a shard that has not run yet)
  std::map<std::string, int> by_path;  // label path -> frames
  // Jobs that track the hand: where the network's crops came from -> frames
  // ("detector": the frame was detected, "previous_label": it was not).
  std::map<std::string, int> by_crops;
  double frame_seconds = 0;  // summed per-frame time of the latest records
  // The same per stage (FrameRecord::stages; records of older logs have none): wall
  // seconds spent inside each stage, summed over frames. Stages run side by side on
  // `threads` threads, so they add up to more than wall_seconds.
  std::map<std::string, double> stage_seconds;
  int stage_frames = 0;     // frames whose records carry stage times
  double wall_seconds = 0;  // wall time of this run (0 for a merge: not written)
  int threads = 0;          // threads the run labelled frames on (0: unknown, merge)
  int skipped = 0;          // done in an earlier run and skipped (run only)
  std::vector<std::pair<std::string, std::string>> failures;  // frame, reason
  // Where the job's 2D keypoints came from (FrameSource::KeypointsSource, or the
  // network's own); empty when not known (a merge without the job's source).
  std::string keypoints_2d_source;
  // group -> metric -> mean over frames
  std::map<std::string, std::map<std::string, MetricMean>> metrics;

  nlohmann::json ToJson() const;
  // A few lines for the terminal at the end of a run or merge.
  std::string ToText() const;
  // "Where the time went": stage_seconds as a table, stages grouped by the name before
  // the dot ("detect" over "detect.palm", ...), groups and their parts longest first,
  // with their share of all stages and per frame (a group's parts under 0.1 % of all
  // in one row "(N more)"); "" without stage times.
  std::string StageTable() const;
  // The same as a Markdown section (for reports).
  std::string ToMarkdown() const;
};

// Summarises the latest record of each of `frames` (frames without a record count as
// missing).
LabelSummary Summarize(const std::vector<std::string>& frames,
                       const std::map<std::string, FrameRecord>& records);

}  // namespace handlabel
