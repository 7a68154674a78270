#pragma once
// The layout of a labeling job's output folder (output.dir) and the merge of shards:
//   job.json                          job name and hash (a folder holds one job)
//   labels/<frame>.json               one label per frame (label_record.h)
//   meshes/<frame>.ply|.obj           optional meshes
//   overlays/<frame>/<camera>.jpg     optional overlay pictures (or .png)
//   detections/<frame>.json           the in-job detector's answers
//   (evidence.keypoints_2d:
//                                     detector), in the format `handlabel detect` writes
//   shards/shard-<i>-of-<N>.jsonl     resume log of shard i (frame_log.h)
//   shards/shard-<i>-of-<N>.summary.json   what that shard's last run did
//   manifest.json, summary.json, summary.md   written by merge (and by a 1-shard run)

#include <map>
#include <string>
#include <vector>

#include "pipeline/frame_log.h"
#include "pipeline/label_summary.h"
#include "pipeline/shard.h"

namespace handlabel {

std::string ShardLogPath(const std::string& output_dir, const ShardSpec& shard);
std::string ShardSummaryPath(const std::string& output_dir, const ShardSpec& shard);
std::string JobStampPath(const std::string& output_dir);
std::string ManifestPath(const std::string& output_dir);
std::string SummaryJsonPath(const std::string& output_dir);
std::string SummaryMarkdownPath(const std::string& output_dir);
// `format`: the job's output.overlay_format, the file's extension (jpg | png).
std::string OverlayPath(const std::string& output_dir, const std::string& frame,
                        const std::string& camera, const std::string& format);
// The folder of the in-job detector's answers, and one frame's file in it.
std::string JobDetectionsDir(const std::string& output_dir);
std::string JobDetectionsPath(const std::string& output_dir, const std::string& frame);

// The latest record per frame over every shard log in the folder (logs of any shard
// count, so a job may be re-sharded between runs). An ok record wins over a failed
// one: labels are deterministic, so any ok label of the job is the label.
std::map<std::string, FrameRecord> ReadShardLogs(const std::string& output_dir);

// Throws InputError, before anything is written, when job.json or a shard log record
// carries another job hash than `job_hash` (the folder holds another job's outputs).
void CheckOutputsBelongToJob(const std::string& output_dir, const std::string& job_hash);

// Joins the shards: every frame of `frames` with its latest record; an ok record whose
// label file is missing or not the file it wrote (size, SHA-256) counts as missing.
// First checks CheckOutputsBelongToJob. `not_labelled`, if given, receives each
// missing frame with why ("f7 (not yet run)"). Writes manifest.json (frames, status,
// path, label file, reason: nothing run-dependent, so it is identical however the job was
// sharded), summary.json and summary.md, each atomically, and returns the summary.
// `keypoints_2d_source` (FrameSource::KeypointsSource) is stated in the summary; ""
// takes it from the shards' summaries (what `merge` knows). `run`: the summary of a
// run of the whole job that merges at its end; its wall time, threads and skipped
// frames go into summary.json (a merge alone knows no wall time).
LabelSummary MergeLabelOutputs(const std::string& output_dir, const std::string& job_name,
                               const std::string& job_hash,
                               const std::vector<std::string>& frames,
                               const std::string& keypoints_2d_source = "",
                               std::vector<std::string>* not_labelled = nullptr,
                               const LabelSummary* run = nullptr);

// Removes leftovers of interrupted atomic writes that belong to `frames` (never other
// shards' files, which may be in flight). Returns how many were removed.
int RemoveStaleFrameTemporaries(const std::string& output_dir,
                                const std::vector<std::string>& frames);

}  // namespace handlabel
