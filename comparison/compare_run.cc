#include "comparison/compare_run.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "capture/capture_format.h"
#include "core/errors.h"
#include "core/option_checks.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "pipeline/frame_metrics.h"
#include "pipeline/label_job.h"
#include "pipeline/label_stage_factory.h"
#include "pipeline/network_stage.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// A refine.min_views no rig reaches: the enough_views check then fails on every
// frame and the fallback policy fits every frame from the 2D evidence alone.
constexpr int kNoViewsEnough = 1000000;

// A native capture's manifest (nullopt for other formats or an unreadable one: the
// frame source reports a bad manifest, naming the field).
std::optional<CaptureManifest> NativeManifest(const JobConfig& job) {
  if (job.input_format != "native") return std::nullopt;
  const fs::path path = fs::path(job.input_path) / kCaptureManifestFile;
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    return ManifestFromJson(nlohmann::json::parse(in), path.string());
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// HO3D-like input (the dataset, or a synthetic capture of its rig preset): the paper
// reports HO3D-MV's AUC over 0-50 mm.
bool Ho3dLike(const JobConfig& job) {
  if (job.input_format == "ho3d") return true;
  const std::optional<CaptureManifest> manifest = NativeManifest(job);
  if (!manifest) return false;
  const nlohmann::json::json_pointer preset("/settings/rig/preset");
  return manifest->generator.contains(preset) && manifest->generator[preset] == "ho3d";
}

bool NeedsNetwork(CompareMethod m) {
  return m == CompareMethod::kNetwork || m == CompareMethod::kNetworkRefine ||
         m == CompareMethod::kFitNetwork2d;
}

}  // namespace

std::string EvidenceText(const JobConfig& job) {
  std::string text = "refine " + ToString(job.refine_mode);
  if (job.refine_mode == RefineMode::kOff) return text + ", no fit";
  if (job.quality.min_views >= kNoViewsEnough) text = "every frame fitted";
  const char* keypoints = job.keypoints == KeypointSource::kNetwork ? "network"
                          : job.keypoints == KeypointSource::kFiles ? "files"
                                                                    : "both";
  const char* masks = job.masks == MaskSource::kNone    ? "none"
                      : job.masks == MaskSource::kFiles ? "files"
                                                        : "network";
  text += std::string(", 2D ") + keypoints;
  if (job.keypoints != KeypointSource::kNetwork) text += " (" + job.keypoint_files + ")";
  text += std::string(", masks ") + masks;
  if (job.masks == MaskSource::kFiles) text += " (" + job.mask_files + ")";
  if (!job.ignore_views.empty())
    text += ", " + std::to_string(job.ignore_views.size()) + " views ignored";
  return text;
}

const std::vector<CompareMethod>& AllCompareMethods() {
  static const std::vector<CompareMethod> all = {
      CompareMethod::kNetwork, CompareMethod::kNetworkRefine,
      CompareMethod::kFitNetwork2d, CompareMethod::kFitDetections,
      CompareMethod::kFitExact2d};
  return all;
}

std::string ToString(CompareMethod m) {
  switch (m) {
    case CompareMethod::kNetwork:
      return "network";
    case CompareMethod::kNetworkRefine:
      return "network_refine";
    case CompareMethod::kFitNetwork2d:
      return "fit_network_2d";
    case CompareMethod::kFitDetections:
      return "fit_detections";
    case CompareMethod::kFitExact2d:
      return "fit_exact_2d";
  }
  return "?";
}

std::string Describe(CompareMethod m) {
  switch (m) {
    case CompareMethod::kNetwork:
      return "POEM network";
    case CompareMethod::kNetworkRefine:
      return "network + refine";
    case CompareMethod::kFitNetwork2d:
      return "Multi-view Fit. (network 2D)";
    case CompareMethod::kFitDetections:
      return "fit from capture's 2D";
    case CompareMethod::kFitExact2d:
      return "fit from exact 2D";
  }
  return "?";
}

CompareMethod ParseCompareMethod(const std::string& name, const std::string& source,
                                 const std::string& field) {
  for (CompareMethod m : AllCompareMethods()) {
    if (ToString(m) == name) return m;
  }
  throw InputError(source, field,
                   "network, network_refine, fit_network_2d, fit_detections or "
                   "fit_exact_2d",
                   "'" + name + "'");
}

void CompareOptions::Check(const std::string& source) const {
  if (out_dir.empty()) throw InputError(source, "--out", "an output folder");
  RequireAtLeast(source, "--auc-max-mm", auc_max_mm, 0, ">= 0 (0: from the input)");
  RequireAtLeast(source, "--auc-steps", auc_steps, 2);
  for (int v : ablation_views) {
    RequireAtLeast(source, "--ablation-views", v, 1, "view counts >= 1");
  }
  RequireAtLeast(source, "--ablation-frames", ablation_frames, 1);
  RequireAtLeast(source, "--worst-frames", worst_frames, 0);
  RequireGreater(source, "--qa-error-mm", qa_error_mm, 0);
  for (const std::string& dir : qa_selection) {
    if (!fs::exists(fs::path(dir) / "compare.json")) {
      throw InputError(source, "--qa-selection", "compare output folders (compare.json)",
                       dir);
    }
  }
}

JobConfig CompareCaptureJob(const std::string& capture_dir, const std::string& weights,
                            const std::string& frames, int max_frames, int threads,
                            uint64_t seed) {
  JobConfig job;
  job.source_file = "handlabel compare";
  job.name = "compare";
  job.seed = seed;
  job.input_format = "native";
  job.input_path = fs::path(capture_dir).lexically_normal().string();
  if (!frames.empty()) job.frames = frames;
  job.max_frames = max_frames;
  job.network_weights = weights;
  job.threads = threads;
  job.refine_mode = weights.empty() ? RefineMode::kAlways : RefineMode::kFallback;
  job.keypoints = weights.empty() ? KeypointSource::kFiles : KeypointSource::kBoth;
  job.masks = MaskSource::kFiles;
  job.network_mask_sigma_px = job.keypoints == KeypointSource::kNetwork ? 2.0 : 16.0;
  job.overlays = false;
  return job;
}

JobConfig MethodJob(const JobConfig& base, CompareMethod method, const std::string& out,
                    std::string* why_not) {
  why_not->clear();
  JobConfig job = base;
  job.output_dir = (fs::path(out) / "methods" / ToString(method)).string();
  job.overlays = false;
  job.meshes.clear();
  job.evaluate = true;
  job.baseline = false;
  if (NeedsNetwork(method) && base.network_weights.empty()) {
    *why_not = "no network weights (network.weights / --weights)";
    return job;
  }
  const std::optional<CaptureManifest> manifest = NativeManifest(base);
  const std::map<std::string, std::string> files =
      manifest ? manifest->files : std::map<std::string, std::string>{};
  switch (method) {
    case CompareMethod::kNetwork:
      job.refine_mode = RefineMode::kOff;
      break;
    case CompareMethod::kNetworkRefine:
      job.refine_mode = RefineMode::kAlways;
      break;
    case CompareMethod::kFitNetwork2d:
      job.refine_mode = RefineMode::kFallback;
      job.quality.min_views = kNoViewsEnough;
      job.keypoints = KeypointSource::kNetwork;
      job.masks = MaskSource::kNetwork;  // RunComparison drops it without a mask head
      job.network_mask_sigma_px = 2.0;   // the job file's default for network 2D
      job.fit.init = "triangulate";
      break;
    case CompareMethod::kFitDetections:
      if (base.input_format == "ho3d" || base.input_format == "oakink") {
        *why_not = "the " + base.input_format + " input has no 2D keypoint files";
        return job;
      }
      job.network_weights.clear();
      job.refine_mode = RefineMode::kAlways;
      job.keypoints = KeypointSource::kFiles;
      if (job.masks == MaskSource::kNetwork) job.masks = MaskSource::kFiles;
      if (base.input_format == "dexycb") job.masks = MaskSource::kNone;
      break;
    case CompareMethod::kFitExact2d:
      if (base.input_format != "native" || !files.count(kFileKeypoints)) {
        *why_not =
            "exact 2D projections exist only in synthetic native captures "
            "(keypoints/)";
        return job;
      }
      job.network_weights.clear();
      job.refine_mode = RefineMode::kAlways;
      job.keypoints = KeypointSource::kFiles;
      job.keypoint_files = "keypoints";
      job.masks = files.count(kFileMask) ? MaskSource::kFiles : MaskSource::kNone;
      job.mask_files = files.count(kFileMask) ? "truth" : "auto";
      break;
  }
  job.Check(job.source_file);
  return job;
}

std::optional<LabelRecord> MethodLabel(const MethodRun& run, const std::string& frame) {
  if (!run.why_not.empty()) return std::nullopt;
  const std::string path = LabelFilePath(run.output_dir, frame);
  if (!fs::exists(path)) return std::nullopt;
  return ReadLabelFile(path);
}

namespace {

using Truths = std::map<std::string, FrameGroundTruth>;

// Scores a method's labels against the truth with hand/metrics.h.
MethodScores ScoreLabels(const MethodRun& run, const std::vector<std::string>& frames,
                         const Truths& truths, const PckOptions& pck) {
  MethodScores s;
  std::vector<Eigen::VectorXd> joints, vertices;
  std::vector<MotionFrame> motion;
  const std::vector<int64_t> numbers = MotionFrameNumbers(frames);
  bool all_vertices = true;
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::string& frame = frames[i];
    const auto truth = truths.find(frame);
    if (truth == truths.end()) continue;
    const std::optional<LabelRecord> label = MethodLabel(run, frame);
    if (!label) continue;
    motion.push_back({numbers[i], label->mesh.keypoints, truth->second.keypoints});
    const FrameGroundTruth& t = truth->second;
    const bool with_vertices =
        t.vertices.rows() > 0 && t.vertices.rows() == label->mesh.vertices.rows();
    all_vertices = all_vertices && with_vertices;
    const Points3d none(0, 3);
    s.frames.push_back(frame);
    s.per_frame.push_back(EvaluateHandFrame(label->mesh.keypoints, t.keypoints,
                                            with_vertices ? label->mesh.vertices : none,
                                            with_vertices ? t.vertices : none));
    joints.push_back(PointErrors(label->mesh.keypoints, t.keypoints));
    vertices.push_back(with_vertices ? PointErrors(label->mesh.vertices, t.vertices)
                                     : Eigen::VectorXd());
  }
  const int n = static_cast<int>(s.frames.size());
  if (n == 0) return s;
  s.joint_errors.resize(n, joints[0].size());
  for (int f = 0; f < n; ++f) s.joint_errors.row(f) = joints[f].transpose();
  if (all_vertices) {
    s.vertex_errors.resize(n, vertices[0].size());
    for (int f = 0; f < n; ++f) s.vertex_errors.row(f) = vertices[f].transpose();
    s.vertex_pck = ComputePck(s.vertex_errors, pck);
  }
  s.joint_pck = ComputePck(s.joint_errors, pck);
  s.motion = ComputeMotionMetrics(motion);
  for (const HandFrameMetrics& m : s.per_frame) {
    s.mean.mpjpe += m.mpjpe / n;
    s.mean.rr_mpjpe += m.rr_mpjpe / n;
    s.mean.pa_mpjpe += m.pa_mpjpe / n;
    s.mean.mpvpe += m.mpvpe / n;
    s.mean.rr_mpvpe += m.rr_mpvpe / n;
    s.mean.pa_mpvpe += m.pa_mpvpe / n;
  }
  return s;
}

// One comparison: the frames and their truth, then each method as a job.
class ComparisonRun {
 public:
  ComparisonRun(const JobConfig& base, const CompareOptions& options, std::ostream* log)
      : base_(base), options_(options), log_(log) {}

  CompareResult Run() {
    const Clock::time_point start = Clock::now();
    options_.Check("command line");
    fs::create_directories(options_.out_dir);
    LoadFramesAndTruth();
    const std::vector<CompareMethod> methods =
        options_.methods.empty() ? AllCompareMethods() : options_.methods;
    for (CompareMethod m : methods) result_.methods.push_back(RunMethod(m, base_, {}));
    RunAblation();
    if (log_ && memo_->hits() > 0) {
      *log_ << "compare: " << memo_->hits()
            << " network answers reused (same weights, same crops: predicted once)\n";
    }
    result_.wall_seconds = SecondsSince(start);
    return result_;
  }

 private:
  void LoadFramesAndTruth() {
    const std::unique_ptr<FrameSource> source = BuildFrameSource(base_);
    result_.job_name = base_.name;
    result_.input = base_.input_format + " " + base_.input_path;
    result_.frames = JobFrames(base_, *source);
    if (result_.frames.empty()) {
      throw InputError(base_.source_file, "input.frames", "at least one frame", "none");
    }
    for (const std::string& frame : result_.frames) {
      const FrameInput input = source->Load(frame);
      if (result_.cameras.empty()) {
        for (size_t v = 0; v < input.rig.size(); ++v)
          result_.cameras.push_back(input.rig[v].name);
      }
      if (input.ground_truth) truths_[frame] = *input.ground_truth;
    }
    result_.auc_max_mm = options_.auc_max_mm > 0 ? options_.auc_max_mm
                         : Ho3dLike(base_)       ? 50.0
                                                 : 20.0;
    pck_.max_threshold = result_.auc_max_mm / 1000;
    pck_.steps = options_.auc_steps;
  }

  // Runs one method's job (with `frames` / `ignore_views` overrides for the
  // ablation) and scores it; any error becomes the row's reason.
  MethodRun RunMethod(CompareMethod method, const JobConfig& base,
                      const std::string& sub_dir) {
    MethodRun run;
    run.method = method;
    const std::string out = sub_dir.empty() ? options_.out_dir : sub_dir;
    try {
      run.job = MethodJob(base, method, out, &run.why_not);
      if (!run.why_not.empty()) return Logged(run);
      if (method == CompareMethod::kFitNetwork2d && !NetworkHasMasks(run.job)) {
        run.job.masks = MaskSource::kNone;  // weights without a mask head
      }
      run.output_dir = run.job.output_dir;
      const BuiltLabelStages stages = BuildLabelStages(run.job, memo_);
      if (stages.predictor) {
        run.parameters = stages.predictor->num_parameters;
        network_has_masks_ = stages.predictor->predicts_masks;
      }
      run.evidence = EvidenceText(run.job);
      LabelRunOptions run_options;
      run_options.force = true;
      const Clock::time_point t = Clock::now();
      const double saved_before = memo_->saved_seconds();
      const LabelSummary summary = RunLabelJob(run.job, stages.Set(), run_options);
      run.wall_seconds = SecondsSince(t);
      // The row's time is the method's own: the network answers it was given from
      // another method's run count as if computed here.
      const double saved = memo_->saved_seconds() - saved_before;
      run.frames = summary.frames;
      run.ok = summary.ok;
      run.failed = summary.failed;
      run.by_path = summary.by_path;
      if (!summary.failures.empty()) run.first_failure = summary.failures[0].second;
      run.seconds_per_frame =
          (summary.frame_seconds + saved) / std::max(1, summary.frames);
      run.threads = run.job.threads > 0
                        ? run.job.threads
                        : static_cast<int>(std::thread::hardware_concurrency());
      if (run.ok == 0) {
        run.why_not = "every frame failed: " + run.first_failure;
        return Logged(run);
      }
      run.scores = ScoreLabels(run, result_.frames, truths_, pck_);
      run.has_truth = !run.scores.frames.empty();
    } catch (const std::exception& e) {
      run.why_not = e.what();
    }
    return Logged(run);
  }

  // Whether the weights have a mask head (loads them once if no method did yet).
  bool NetworkHasMasks(const JobConfig& job) {
    if (!network_has_masks_) network_has_masks_ = LoadNetworkStage(job).predicts_masks;
    return *network_has_masks_;
  }

  MethodRun Logged(const MethodRun& run) const {
    if (!log_) return run;
    *log_ << "compare: " << ToString(run.method) << ": ";
    if (!run.why_not.empty()) {
      *log_ << "not run: " << run.why_not << "\n";
    } else {
      *log_ << run.ok << "/" << run.frames << " labelled in " << run.wall_seconds << " s";
      if (run.has_truth) *log_ << ", MPJPE " << 1000 * run.scores.mean.mpjpe << " mm";
      if (run.has_truth && run.scores.motion.triples > 0) {
        *log_ << ", acceleration error " << 1000 * run.scores.motion.acceleration_error
              << " mm/frame^2";
      }
      *log_ << "\n";
    }
    return run;
  }

  // Fitting methods with the evidence of the first k cameras only, on the first
  // ablation_frames frames; the all-views cell comes from the main run.
  void RunAblation() {
    const int all_views = static_cast<int>(result_.cameras.size());
    const int n = std::min<int>(options_.ablation_frames, result_.frames.size());
    const std::vector<std::string> frames(result_.frames.begin(),
                                          result_.frames.begin() + n);
    std::vector<int> counts = options_.ablation_views;
    if (options_.ablation_all_counts) {
      for (int k = 2; k < all_views; ++k) counts.push_back(k);
    }
    for (int k : counts) {  // asked for by number: said, not dropped silently
      if (k >= all_views && log_) {
        *log_ << "compare: note: --ablation-views " << k << " left out: the input has "
              << all_views << " cameras (an ablation keeps fewer; all " << all_views
              << " are the main run)\n";
      }
    }
    for (const MethodRun& main : result_.methods) {
      if (!main.why_not.empty()) continue;
      for (int k : counts) {
        AblationCell cell;
        cell.method = main.method;
        cell.views = k;
        if (k >= all_views) {
          cell.why_not = "the input has " + std::to_string(all_views) + " cameras";
          result_.ablation.push_back(cell);
          continue;
        }
        if (main.method == CompareMethod::kNetwork ||
            main.method == CompareMethod::kNetworkRefine) {
          cell.why_not =
              "the network's weights take all " + std::to_string(all_views) + " views";
          result_.ablation.push_back(cell);
          continue;
        }
        JobConfig base = base_;
        base.frames = Join(frames, ",");
        base.max_frames = 0;
        base.ignore_views.assign(result_.cameras.begin() + k, result_.cameras.end());
        const std::string dir =
            (fs::path(options_.out_dir) / "ablation" / (std::to_string(k) + "_views"))
                .string();
        const MethodRun run = RunMethod(main.method, base, dir);
        result_.ablation.push_back(AblationCellOf(run, k));
      }
      // All views: the main run on the same frames.
      if (counts.empty()) continue;
      MethodRun subset = main;
      subset.scores = ScoreLabels(main, frames, truths_, pck_);
      result_.ablation.push_back(AblationCellOf(subset, all_views));
    }
  }

  static AblationCell AblationCellOf(const MethodRun& run, int views) {
    AblationCell cell;
    cell.method = run.method;
    cell.views = views;
    cell.why_not = run.why_not;
    cell.frames = static_cast<int>(run.scores.frames.size());
    cell.mpjpe_mm = 1000 * run.scores.mean.mpjpe;
    cell.mpvpe_mm = run.scores.vertex_errors.cols() > 0
                        ? 1000 * run.scores.mean.mpvpe
                        : std::numeric_limits<double>::quiet_NaN();
    cell.seconds_per_frame = run.seconds_per_frame;
    return cell;
  }

  const JobConfig& base_;
  const CompareOptions& options_;
  std::ostream* log_;
  CompareResult result_;
  Truths truths_;
  PckOptions pck_;
  // The methods that run the network on the same frames share its answers.
  std::shared_ptr<PredictionMemo> memo_ = std::make_shared<PredictionMemo>();
  std::optional<bool> network_has_masks_;
};

}  // namespace

CompareResult RunComparison(const JobConfig& base, const CompareOptions& options,
                            std::ostream* log) {
  return ComparisonRun(base, options, log).Run();
}

}  // namespace handlabel
