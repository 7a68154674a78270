#pragma once
// The resume log of one labeling shard: an append-only JSON-lines file with one record
// per frame that reached a final state. A record is appended only after the frame's
// outputs were renamed into place, so "in the log with status ok" implies "outputs
// complete". A crash can leave a partial last line; it is ignored on load.

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace handlabel {

struct FrameRecord {
  std::string frame;   // frame id
  std::string status;  // "ok" or "failed"
  std::string path;    // which stage produced the label ("network", "refined", "fit")
  std::string reason;  // why it failed (empty when ok)
  double seconds = 0;  // wall time spent on the frame: the sum of `stages`
  // Where `seconds` went: wall seconds per stage ("read", "detect.palm", "network",
  // "fit.keypoints", "write.labels", ...; docs/labeling-jobs.md, "Where the time went"),
  // the stages that ran on the frame only; empty in older logs.
  std::map<std::string, double> stages;
  // Per-frame errors against ground truth, "<group>/<metric>" -> value (label_summary.h);
  // empty when the capture has no ground truth.
  std::map<std::string, double> metrics;
  // With ground truth: the 21 keypoints (SNAP order, x y z each, millimetres to 1 um)
  // each metric group was scored on and the truth's ("truth"), for the motion metrics
  // over consecutive frames; empty otherwise and in older logs.
  std::map<std::string, std::vector<double>> keypoints_mm;
  // The label file as written (ok records): its size and SHA-256, checked on resume
  // and merge so that a truncated or replaced label is never taken as done. -1 / ""
  // in logs written before these were recorded.
  int64_t label_bytes = -1;
  std::string label_sha256;
  std::string job_hash;  // the job the record belongs to ("" in older logs)
  // Jobs that track the hand (evidence.detector_every): where the network's crops came
  // from, "detector" or "previous_label"; "" otherwise.
  std::string crops;
  // When the frame's 2D detections hold several hands (`detect --max-hands`): which one
  // the job took, "hand 2 of 2 (left)" (FrameInput::evidence_hand); "" otherwise.
  std::string hand;
};

// Why the label file at `label_path` is not the one `record` (an ok record) wrote:
// missing, another size or another checksum; "" when it is. Records without a
// checksum (older logs) need a label that exists and parses.
std::string LabelFileProblem(const FrameRecord& record, const std::string& label_path);

class FrameLog {
 public:
  // Loads `path` if it exists. Throws InputError naming the file and line for a
  // malformed complete line (a partial last line is not an error: it is cut off, so
  // that the next append starts on a line of its own).
  explicit FrameLog(std::string path);

  // True if the frame finished with status ok.
  bool IsDone(const std::string& frame) const;
  // Appends durably; thread-safe. A later record for the same frame supersedes.
  void Record(const FrameRecord& record);
  // Latest record per frame, sorted by frame id.
  std::vector<FrameRecord> Latest() const;
  const std::string& path() const { return path_; }

  // Reads a log without keeping it open for appends (merge, reports).
  static std::vector<FrameRecord> Read(const std::string& path);

 private:
  std::string path_;
  mutable std::mutex mutex_;
  std::map<std::string, FrameRecord> latest_;
};

}  // namespace handlabel
