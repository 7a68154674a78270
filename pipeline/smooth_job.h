#pragma once
// The smoothing pass of a labeling job over time (job section `sequence`, issue 45;
// docs/labeling-jobs.md "Sequences"): it reads the job's per-frame labels and the same
// 2D evidence they were fitted to, and writes smoothed labels, in the same layout, to
// <output.dir>/smoothed/ (labels/<frame>.json, meshes, summary.json). The per-frame
// labels are never touched.
//
//   segments  the job's frames in order, cut where the chain breaks: a frame without a
//             per-frame label with parameters, or neighbours whose ids are not
//             consecutive numbers (pipeline/frame_metrics.h MotionFrameNumbers)
//   shape     one for the whole job (SequenceSmoother::SequenceShape over every
//             labelled frame), so every window and every shard holds the same hand
//   windows   per segment, `window` frames every window - overlap frames from the
//             segment's start (the last one ends at the segment's end); each is one
//             Ceres problem (fitting/sequence_smoother.h)
//   blend     a frame in two windows gets their parameters weighted by ramps across the
//             overlap (BlendWeight), so the result is continuous where windows meet
// Windows are laid out over the whole job, not the shard: a shard solves every window
// that covers one of its frames, reading its neighbours' labels and evidence as
// context, so shards meet on the overlaps and sharded labels equal a whole run's.
// Deterministic (each window is solved on one thread; windows run in parallel) and
// resumable: a smoothed label is written atomically once its windows are solved, and a
// re-run skips frames whose smoothed label exists (--force: all again). The summary
// (written when every labelled frame of the job is smoothed) compares per-frame and
// smoothed labels: MPJPE, acceleration error, jitter and bone-length error against
// ground truth where the capture has it, jitter and how far smoothing moved them.

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "hand/hand_lbs.h"
#include "pipeline/job_config.h"
#include "pipeline/shard.h"

namespace handlabel {

// One window over positions [begin, end) of a segment.
struct WindowSpan {
  int begin = 0;
  int end = 0;
};

// The windows over a segment of `length` frames (>= 1): starts 0, s, 2s, ... with
// s = window - overlap while a window ends inside the segment, then one ending at the
// segment's end; a segment shorter than a window is one window.
std::vector<WindowSpan> SegmentWindows(int length, int window, int overlap);

// Weight of `span` at position `i` (inside it) of a segment of `length` frames:
// rising linearly over the first `overlap` frames and falling over the last ones,
// except at the segment's own ends; positive inside the span. The weights of the
// windows covering a frame are normalised by their sum.
double BlendWeight(const WindowSpan& span, int i, int length, int overlap);

// Weighted mean of hand parameters that lie close together (the same frame solved in
// two windows): orientations as unit quaternions, other values linearly; weights > 0.
HandParams BlendParams(const std::vector<std::pair<double, HandParams>>& weighted);

struct SmoothRunOptions {
  ShardSpec shard;              // which frames to write (windows extend beyond it)
  bool force = false;           // smooth every frame of the shard again
  std::ostream* log = nullptr;  // progress and summary; nullptr = quiet
};

struct SmoothSummary {
  int frames = 0;      // of the shard
  int smoothed = 0;    // written now
  int skipped = 0;     // smoothed by an earlier run
  int unlabelled = 0;  // without a per-frame label with parameters: not smoothed
  int windows = 0;     // solved now
  // Set when every labelled frame of the job is smoothed: summary.json's content.
  nlohmann::json report;
};

// Throws InputError when the job cannot be smoothed (2D evidence that is not on disk:
// evidence.keypoints_2d network, both or detector; a PCA pose; no per-frame labels of
// this job; smoothed labels of other settings without force).
SmoothSummary RunSmoothJob(const JobConfig& job, const SmoothRunOptions& options);

// <output_dir>/smoothed: where the smoothed labels go.
std::string SmoothedOutputDir(const std::string& output_dir);

}  // namespace handlabel
