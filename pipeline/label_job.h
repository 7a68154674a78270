#pragma once
// The labeling runner: for the frames of one shard, read -> batched network
// inference -> quality checks -> refine or fallback fit (label_policy.h) -> atomic
// writes (label_record.h), with TBB over frames (four pipeline stages: hand out
// batches, read, network, label and write). With fit.init previous the same steps run
// one frame at a time in the job's frame order. `handlabel fit` is this runner on a
// job without a network (fit_capture.h).
//
// Tracking (evidence.detector_every N > 1, LabelStageSet::find_keypoints_2d): the
// detector costs more than the network, so it runs only on every N-th frame of the job
// (and a shard's first frame); a frame in between gives the network crops cut around
// the previous frame's label moved on by its last step (FrameInput::crop_prior), and
// is detected and labelled as usual only when that answer fails its checks. Frames run
// in order within runs that start at detected frames, the runs in parallel.
//
// Video mode (evidence.detector_mode: video, LabelStageSet::start_video_track): a run
// (palm detection in every view) starts at the shard's first frame to do, at every
// detector_palm_every-th frame of the job and after a gap (frames done before, or a
// frame that failed to read), so shards and resumed runs differ from one whole run only
// at such starts. A run's frames are detected in order, each from the previous frame's
// 3D hand (views in parallel inside); runs go in parallel, each frame fitted and
// written after its detection. With a network or fit.init previous, frames are read in
// parallel and detected one at a time in the job's frame order instead.
//
//  - Resume: a frame is finished once its files are renamed into place and its record
//    appended to the shard log (frame_log.h). A re-run with resume skips finished
//    frames, so `kill -9` at any moment loses no finished frame; leftovers of
//    interrupted writes (*.tmp.<pid>) of the shard's frames are removed at start.
//  - Failure isolation: a frame that throws at any stage is recorded as failed with
//    the exception's message; the job goes on. A re-run tries failed frames again.
//  - Shards: ShardSpec picks a deterministic contiguous part of the frames (shard.h).
//    A run of the whole job (shard 0/1) also merges (manifest + summary).
//  - One writer: the run holds its shard's lock and the folder's shared lock
//    (output_lock.h) from planning to the end; a finished frame's record carries the
//    label file's size and SHA-256, checked on resume (frame_log.h).

#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "pipeline/job_config.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stages.h"
#include "pipeline/label_summary.h"
#include "pipeline/shard.h"

namespace handlabel {

// Draws the label onto every view of the frame (mesh and keypoints); implementations
// write with WriteFileAtomically. Thread-safe.
class OverlayWriter {
 public:
  virtual ~OverlayWriter() = default;
  virtual void Write(const std::string& output_dir, const FrameInput& frame,
                     const LabelRecord& label) const = 0;
};

// What a job runs with; built from the job by label_stage_factory.h, or by tests.
struct LabelStageSet {
  const FrameSource* source = nullptr;      // required
  const NetworkStage* predictor = nullptr;  // nullptr: the job has no network
  const LabelFitter* fitter = nullptr;      // nullptr: refine off and no baseline
  const OverlayWriter* overlays = nullptr;  // nullptr: no overlay pictures
  std::string hand_model_name;              // recorded in provenance
  HandSide side = HandSide::kRight;
  Faces faces;  // for mesh files
  // A job that tracks the hand (evidence.detector_every > 1): the source loads frames
  // without their 2D and this finds it for the frames that need it; empty otherwise.
  std::function<void(FrameInput*)> find_keypoints_2d;
  // Video mode (evidence.detector_mode: video): the source loads frames without their
  // 2D; each call starts a track that finds it for the frames handed to it in order,
  // one call at a time: palm detection in every view on its first frame, then each
  // frame's regions from the previous frame's answer. Tracks share nothing, so runs
  // of frames can go in parallel. Empty otherwise.
  std::function<std::function<void(FrameInput*)>()> start_video_track;
  // Writes the in-job detector's answer on a frame into the output folder
  // (label_outputs.h: detections/<frame>.json), once the frame is labelled or has
  // failed; nothing for a frame the detector did not run on. Empty: no detector.
  std::function<void(const std::string& output_dir, const FrameInput& frame)>
      write_detections;
};

struct LabelRunOptions {
  ShardSpec shard;              // which part of the frames (default: all)
  bool resume = false;          // skip frames finished by earlier runs
  bool force = false;           // label every frame again (discards the shard's log)
  bool interactive = false;     // progress bar instead of plain lines
  std::ostream* log = nullptr;  // progress and summary; nullptr = quiet
};

// Hash of everything in the job that can change a label (inputs, cameras, the hand
// model setting, the weights' content, refine mode and thresholds, evidence, fit
// settings, seed), not of where the outputs go or how many threads run. SHA-256 hex.
// Paths enter as written (input.path, hand_model: a file path or "capsule"), not the
// files' content, except the weights, whose SHA-256 the network reports.
std::string JobHash(const JobConfig& job, const std::string& weights_sha256);

// The job's frames from every frame of the capture, per job field input.frames:
// "all", "a:b" (half-open range of positions in the sorted list) or "id,id,...".
// Throws InputError naming `source` and `field` (the job's input.frames, or a flag) for
// an unknown id or a bad range.
std::vector<std::string> SelectFrames(const std::vector<std::string>& all_frames,
                                      const std::string& spec, const std::string& source,
                                      const std::string& field = "input.frames");

// The job's frames: SelectFrames over the source's frames per input.frames, then the
// first input.max_frames of them.
std::vector<std::string> JobFrames(const JobConfig& job, const FrameSource& source);

// Runs the shard; returns its summary (also written to the shard's summary file).
// Throws InputError when the output folder belongs to another job (unless force), is
// in use by another process (the same shard, a merge, or anything during a --force
// of another job), or holds finished frames of this shard and neither resume nor
// force is set.
LabelSummary RunLabelJob(const JobConfig& job, const LabelStageSet& stages,
                         const LabelRunOptions& options);

}  // namespace handlabel
