#pragma once
// `handlabel compare`: every method a user chooses between, run on the same frames of
// one capture, with the POEM paper's metrics side by side (its Table 1 layout):
//   network          the network's mesh alone (refine.mode off)
//   network_refine   the network's mesh refined by the fitter (refine.mode always)
//   fit_network_2d   the paper's "Multi-view Fit." baseline: a fit from the network's
//                    own 2D keypoints (and silhouettes, with a mask head) alone
//   fit_detections   a fit from the capture's 2D keypoint files (detections/ when the
//                    capture has them) and mask files: `handlabel fit`
//   fit_exact_2d     a fit from exact 2D projections and true masks (synthetic native
//                    captures only): the upper bound of fitting
// Each method is a labeling job (label_job.h) derived from one base job, run by the
// job runner into <out>/methods/<method>/; its labels are then scored against the
// capture's ground truth with hand/metrics.h. So a method's numbers are those of
// `label` (or `fit`) with the same job fields: nothing is computed a second way.
// fit_network_2d is the job `refine.mode: fallback` with `refine.min_views` above the
// rig's view count (the enough_views check fails on every frame, so every label is the
// fallback fit from the network's 2D evidence alone).
// A method that cannot run (no weights, no exact 2D) keeps its row with the reason.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "hand/metrics.h"
#include "pipeline/job_config.h"
#include "pipeline/label_record.h"

namespace handlabel {

enum class CompareMethod {
  kNetwork,
  kNetworkRefine,
  kFitNetwork2d,
  kFitDetections,
  kFitExact2d
};
const std::vector<CompareMethod>& AllCompareMethods();
std::string ToString(CompareMethod method);  // "network", "network_refine", ...
std::string Describe(CompareMethod method);  // the row's title in tables
// Throws InputError naming `source` and `field` for an unknown name.
CompareMethod ParseCompareMethod(const std::string& name, const std::string& source,
                                 const std::string& field);

struct CompareOptions {
  std::string out_dir;  // the comparison's folder (created); methods/<name>/ inside
  // Methods to run, in table order; empty = all.
  std::vector<CompareMethod> methods;
  // Upper end of the PCK / AUC range in mm; 0 = from the input: 50 for HO3D (the
  // dataset, or a synthetic capture of the ho3d rig preset; as the paper reports
  // HO3D-MV), else 20 (DexYCB-MV, OakInk-MV).
  double auc_max_mm = 0;
  int auc_steps = 20;  // thresholds of the PCK curve (POEM's configs: 20)
  // View-count ablation: view counts to run the fitting methods with (the first k
  // cameras of the rig keep their evidence, the others are ignored:
  // evidence.ignore_views); empty = no ablation. A count >= the input's cameras is
  // not run: a note says so and its cells say why.
  std::vector<int> ablation_views;
  // Every count from 2 to the input's cameras - 1 (`--ablation-views all`), besides
  // ablation_views.
  bool ablation_all_counts = false;
  int ablation_frames = 10;  // the first N compared frames enter the ablation (>= 1)
  int worst_frames = 3;      // frames shown with every method's overlay (>= 0)
  // Quality-check study: a network answer is "bad" when its MPJPE exceeds this (mm).
  double qa_error_mm = 8.0;
  // Quality-check study: earlier compare output folders whose network answers choose
  // the thresholds (every frame of this run is then held out); empty = choose on this
  // run's frames at even positions, judge on the odd ones (comparison/compare_qa.h).
  std::vector<std::string> qa_selection;
  // Throws InputError naming the flag.
  void Check(const std::string& source) const;
};

// Errors of one method on the compared frames (metres inside, mm in the table).
struct MethodScores {
  std::vector<std::string> frames;  // frames with a label and ground truth
  std::vector<HandFrameMetrics> per_frame;
  Eigen::MatrixXd joint_errors;    // frames x 21 (metres)
  Eigen::MatrixXd vertex_errors;   // frames x V, 0 columns without true vertices
  PckCurve joint_pck, vertex_pck;  // over the options' range
  HandFrameMetrics mean;           // means over frames
  // Keypoint acceleration error and jitter over the triples of consecutive compared
  // frames (metres per frame^2; triples = 0 when no three compared frames follow
  // each other).
  MotionMetrics motion;
};

struct MethodRun {
  CompareMethod method = CompareMethod::kNetwork;
  std::string why_not;     // non-empty: the method did not run, and why
  std::string output_dir;  // the method's label job folder
  JobConfig job;           // the job it ran as
  std::string evidence;    // EvidenceText(job)
  int frames = 0, ok = 0, failed = 0;
  std::map<std::string, int> by_path;  // labels per path
  std::string first_failure;           // a failed frame's reason, "" if none
  double seconds_per_frame = 0;        // summed per-frame time / frames
  double wall_seconds = 0;             // the method's whole job
  int threads = 0;
  int64_t parameters = 0;  // the network's learned parameters (0: no network)
  bool has_truth = false;  // scores exist
  MethodScores scores;
};

struct AblationCell {
  CompareMethod method = CompareMethod::kFitDetections;
  int views = 0;
  std::string why_not;
  int frames = 0;                     // scored frames
  double mpjpe_mm = 0, mpvpe_mm = 0;  // means over the scored frames
  double seconds_per_frame = 0;
};

struct CompareResult {
  std::string job_name;
  std::string input;                 // the base job's input (format and path)
  std::vector<std::string> frames;   // the compared frames
  std::vector<std::string> cameras;  // the rig's camera names
  double auc_max_mm = 20;
  std::vector<MethodRun> methods;
  std::vector<AblationCell> ablation;
  double wall_seconds = 0;
};

// The base job as `compare --capture C --weights W` describes it: a native capture,
// the network (when weights are given), refine fallback with the capture's detections
// where a view has them (evidence.keypoints_2d both) and mask files.
JobConfig CompareCaptureJob(const std::string& capture_dir, const std::string& weights,
                            const std::string& frames, int max_frames, int threads,
                            uint64_t seed);

// The job one method runs as (output.dir = <out>/methods/<name>), or "" in *why_not
// with the reason it cannot run.
JobConfig MethodJob(const JobConfig& base, CompareMethod method, const std::string& out,
                    std::string* why_not);

// What a method's job fits to, in a few words ("refine always, 2D files (auto),
// masks files (auto)").
std::string EvidenceText(const JobConfig& job);

// Runs every method on the base job's frames, scores them, runs the ablation.
// `log`: one line per method (and the job runner's summaries when verbose).
CompareResult RunComparison(const JobConfig& base, const CompareOptions& options,
                            std::ostream* log);

// The label of `frame` written by a method, if any.
std::optional<LabelRecord> MethodLabel(const MethodRun& run, const std::string& frame);

}  // namespace handlabel
