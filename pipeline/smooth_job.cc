#include "pipeline/smooth_job.h"

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "fitting/sequence_smoother.h"
#include "hand/metrics.h"
#include "pipeline/frame_metrics.h"
#include "pipeline/hand_model_source.h"
#include "pipeline/job_stamp.h"
#include "pipeline/label_job.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_overlay.h"
#include "pipeline/label_policy.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stage_factory.h"
#include "pipeline/output_lock.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

Eigen::Quaterniond QuaternionFromAxisAngle(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < 1e-12) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, v / angle));
}

Eigen::Vector3d AxisAngleFromQuaternion(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q);
  return aa.angle() * aa.axis();
}

// A frame of the job with what smoothing needs of its per-frame label.
struct LabelledFrame {
  std::string id;
  std::optional<LabelRecord> label;  // absent: no usable per-frame label
};

// The settings that make a smoothed label what it is (the stamp of smoothed/).
json SmoothingStamp(const JobConfig& job, const std::string& job_hash,
                    const Eigen::VectorXd& betas) {
  const SequenceSettings& s = job.sequence;
  json stamp = {
      {"job_hash", job_hash},
      {"window", s.window},
      {"overlap", s.overlap},
      {"acceleration_sigma_mm", s.acceleration_sigma_mm},
      {"iterations", s.iterations},
      {"betas", std::vector<double>(betas.data(), betas.data() + betas.size())}};
  // Only when set, so that the stamps of jobs smoothed before the field existed hold.
  if (s.detector_keypoints != "none") stamp["detector_keypoints"] = s.detector_keypoints;
  return stamp;
}

// sequence.detector_keypoints read: none, the shipped MediaPipe model or a file.
std::optional<DetectorKeypointModel> SequenceDetectorKeypoints(const JobConfig& job) {
  return DetectorKeypointModelOfSetting(job.sequence.detector_keypoints, job.source_file,
                                        "sequence.detector_keypoints");
}

// The job's frames with the 2D the per-frame labels were fitted to: the job's own
// source, or for the in-job detector its answers written beside the labels.
std::unique_ptr<FrameSource> EvidenceOnDisk(const JobConfig& job) {
  job.CheckSmoothable();
  if (!job.keypoints_from_detector) return BuildFrameSource(job);
  JobConfig from_files = job;
  from_files.keypoints_from_detector = false;
  from_files.detections = JobDetectionsDir(job.output_dir);
  return BuildFrameSource(from_files);
}

std::string ReportText(const json& report);

class SmoothJobRun {
 public:
  SmoothJobRun(const JobConfig& job, const SmoothRunOptions& options)
      : job_(job), options_(options), out_(SmoothedOutputDir(job.output_dir)) {}

  SmoothSummary Run() {
    lock_ =
        OutputFolderLock::ForSmoothing(job_.output_dir, options_.shard, job_.source_file);
    Plan();
    SolveAndWrite();
    summary_.report = Report();
    if (options_.log && !summary_.report.is_null()) {
      *options_.log << "smoothed: " << ReportText(summary_.report);
    }
    return summary_;
  }

 private:
  // The job's frames and labels, the segments, the sequence's shape, the stamp.
  void Plan() {
    source_ = EvidenceOnDisk(job_);
    model_ = ResolveHandModel(job_.hand_model, source_->side()).model;
    const CeresLabelFitterOptions fit = FitterOptions(job_);
    SequenceSmoothOptions smooth;
    smooth.acceleration_sigma_mm = job_.sequence.acceleration_sigma_mm;
    smooth.iterations = job_.sequence.iterations;
    smoother_.emplace(model_, fit.config, fit.fit, smooth,
                      SequenceDetectorKeypoints(job_));
    if (job_.overlays) {
      overlays_ = std::make_unique<RasterOverlayWriter>(model_, job_.overlay_format);
    }
    job_hash_ = RecordedJobHash(job_.output_dir);
    ReadLabels();
    FindSegments();
    EstimateShape();
    ClaimOutput();
    const std::vector<std::string> mine = FramesOfShard(ids_, options_.shard);
    mine_.insert(mine.begin(), mine.end());
    summary_.frames = static_cast<int>(mine.size());
    for (const LabelledFrame& f : frames_) {
      if (mine_.count(f.id) && !f.label) ++summary_.unlabelled;
    }
    // --force: the shard's earlier smoothed labels go first, so that a forced run
    // killed half-way resumes (without --force) to the new settings, not a mix.
    if (options_.force) {
      for (const std::string& id : mine_) fs::remove(LabelFilePath(out_, id));
    }
  }

  void ReadLabels() {
    ids_ = JobFrames(job_, *source_);
    for (const std::string& id : ids_) {
      LabelledFrame f{id, std::nullopt};
      const std::string path = LabelFilePath(job_.output_dir, id);
      if (fs::exists(path)) {
        LabelRecord label = ReadLabelFile(path);
        if (label.provenance.job_hash != job_hash_) {
          throw InputError(path, "provenance.job_hash", "this job's " + job_hash_,
                           label.provenance.job_hash);
        }
        if (label.params) f.label = std::move(label);
      }
      frames_.push_back(std::move(f));
    }
  }

  // Runs of consecutive labelled frames.
  void FindSegments() {
    const std::vector<int64_t> numbers = MotionFrameNumbers(ids_);
    for (size_t i = 0; i < frames_.size(); ++i) {
      if (!frames_[i].label) continue;
      const bool continues = !segments_.empty() && segments_.back().back() == i - 1 &&
                             numbers[i] == numbers[i - 1] + 1;
      if (!continues) segments_.emplace_back();
      segments_.back().push_back(i);
    }
  }

  void EstimateShape() {
    std::vector<Points3d> keypoints;
    std::vector<HandParams> params;
    for (const LabelledFrame& f : frames_) {
      if (!f.label) continue;
      keypoints.push_back(f.label->mesh.keypoints);
      params.push_back(*f.label->params);
    }
    if (keypoints.empty()) {
      throw InputError(job_.output_dir + "/labels", "", "per-frame labels of the job",
                       "none with MANO parameters");
    }
    betas_ = smoother_->has_detector_model()
                 ? ShapeFromEvidence()
                 : smoother_->SequenceShape(keypoints, params);
  }

  // The shape fitted to the evidence of SequenceSmoothOptions::shape_frames labelled
  // frames spread evenly over the job (the same ones for the same labels).
  Eigen::VectorXd ShapeFromEvidence() const {
    std::vector<size_t> labelled;
    for (size_t i = 0; i < frames_.size(); ++i) {
      if (frames_[i].label) labelled.push_back(i);
    }
    const int count =
        std::min<int>(SequenceSmoothOptions().shape_frames, labelled.size());
    std::vector<SmoothFrame> chosen;
    for (int i = 0; i < count; ++i) {
      const size_t f = labelled[(2 * i + 1) * labelled.size() / (2 * count)];
      chosen.push_back(LoadSmoothFrame(frames_[f]));
    }
    return smoother_->SequenceShapeFromEvidence(chosen);
  }

  // A labelled frame's 2D evidence (the views the per-frame fit saw) and its label.
  SmoothFrame LoadSmoothFrame(const LabelledFrame& f) const {
    const FrameInput input = source_->Load(f.id);
    SmoothFrame frame;
    const std::vector<std::optional<Keypoints2d>> evidence =
        FitEvidence(job_, input, nullptr);
    for (size_t v = 0; v < evidence.size(); ++v) {
      if (evidence[v]) frame.views.push_back({input.rig[v], *evidence[v]});
    }
    frame.start = *f.label->params;
    return frame;
  }

  // smoothed/ holds labels of one smoothing: refuse other settings unless force.
  void ClaimOutput() {
    fs::create_directories(fs::path(out_) / "labels");
    const std::string path = (fs::path(out_) / "smoothing.json").string();
    const json stamp = SmoothingStamp(job_, job_hash_, betas_);
    if (fs::exists(path) && !options_.force) {
      std::ifstream in(path);
      const json recorded = json::parse(in, nullptr, false);
      // A stamp that does not parse is not this job's either (nlohmann's != is false
      // for a discarded value, so it is checked first).
      if (recorded.is_discarded()) {
        throw InputError(path, "", "the smoothing stamp of this job (or --force)",
                         "a file that is not valid JSON");
      }
      if (recorded != stamp) {
        throw InputError(path, "", "the smoothing settings of this job (or --force)",
                         "smoothed labels of other settings or per-frame labels");
      }
      return;
    }
    WriteFileAtomically(path, stamp.dump(1) + "\n");
  }

  bool Todo(size_t frame) const {
    return mine_.count(ids_[frame]) && !fs::exists(LabelFilePath(out_, ids_[frame]));
  }

  // Per segment: the windows covering frames to do, solved a batch at a time; after
  // each batch the frames whose windows are all solved are blended and written.
  void SolveAndWrite() {
    const int threads =
        job_.threads > 0 ? job_.threads : tbb::info::default_concurrency();
    tbb::task_arena arena(threads);
    for (const std::vector<size_t>& segment : segments_) {
      const int length = static_cast<int>(segment.size());
      const std::vector<WindowSpan> spans =
          SegmentWindows(length, job_.sequence.window, job_.sequence.overlap);
      std::vector<int> needed;
      for (size_t w = 0; w < spans.size(); ++w) {
        for (int i = spans[w].begin; i < spans[w].end; ++i) {
          if (Todo(segment[i])) {
            needed.push_back(static_cast<int>(w));
            break;
          }
        }
      }
      for (int i = 0; i < length; ++i) {
        if (mine_.count(ids_[segment[i]]) && !Todo(segment[i])) ++summary_.skipped;
      }
      std::map<int, std::vector<HandParams>> solved;
      const size_t batch = 2 * static_cast<size_t>(threads);
      for (size_t first = 0; first < needed.size(); first += batch) {
        const size_t last = std::min(needed.size(), first + batch);
        std::vector<std::vector<HandParams>> results(last - first);
        arena.execute([&] {
          tbb::parallel_for(first, last, [&](size_t k) {
            results[k - first] = SolveWindow(segment, spans[needed[k]]);
          });
        });
        for (size_t k = first; k < last; ++k) solved[needed[k]] = results[k - first];
        summary_.windows += static_cast<int>(last - first);
        WriteReadyFrames(segment, spans, solved);
      }
    }
  }

  std::vector<HandParams> SolveWindow(const std::vector<size_t>& segment,
                                      const WindowSpan& span) const {
    std::vector<SmoothFrame> frames;
    for (int i = span.begin; i < span.end; ++i) {
      frames.push_back(LoadSmoothFrame(frames_[segment[i]]));
    }
    return smoother_->SmoothWindow(frames, betas_).params;
  }

  void WriteReadyFrames(const std::vector<size_t>& segment,
                        const std::vector<WindowSpan>& spans,
                        const std::map<int, std::vector<HandParams>>& solved) {
    const int length = static_cast<int>(segment.size());
    for (int i = 0; i < length; ++i) {
      if (!Todo(segment[i]) || written_.count(segment[i])) continue;
      std::vector<std::pair<double, HandParams>> weighted;
      std::vector<int> windows;
      bool ready = true;
      for (size_t w = 0; w < spans.size() && ready; ++w) {
        if (i < spans[w].begin || i >= spans[w].end) continue;
        const auto it = solved.find(static_cast<int>(w));
        ready = it != solved.end();
        if (!ready) break;
        weighted.emplace_back(BlendWeight(spans[w], i, length, job_.sequence.overlap),
                              it->second[i - spans[w].begin]);
        windows.push_back(static_cast<int>(w));
      }
      if (!ready) continue;
      WriteSmoothedLabel(segment, spans, windows, i, BlendParams(weighted));
      written_.insert(segment[i]);
      ++summary_.smoothed;
    }
  }

  void WriteSmoothedLabel(const std::vector<size_t>& segment,
                          const std::vector<WindowSpan>& spans,
                          const std::vector<int>& windows, int i,
                          const HandParams& params) const {
    const LabelRecord& per_frame = *frames_[segment[i]].label;
    LabelRecord label = per_frame;
    label.params = params;
    label.mesh = PoseHand(model_, params);
    json window_ids = json::array();
    for (int w : windows) {
      window_ids.push_back(
          {ids_[segment[spans[w].begin]], ids_[segment[spans[w].end - 1]]});
    }
    const double moved_mm =
        PointErrors(label.mesh.keypoints, per_frame.mesh.keypoints).mean() * 1000;
    if (label.fit.is_null()) label.fit = json::object();
    label.fit["smoothing"] = {{"windows", window_ids},
                              {"shape", "sequence"},
                              {"moved_mm", std::round(moved_mm * 1000) / 1000}};
    // Pictures first: a label on disk implies its overlays are complete.
    if (overlays_) overlays_->Write(out_, source_->Load(label.frame), label);
    WriteLabelFiles(out_, label, model_.faces, job_.meshes);
  }

  // The comparison of per-frame and smoothed labels over the whole job, once every
  // labelled frame has a smoothed label; null otherwise.
  json Report() const;

  const JobConfig& job_;
  SmoothRunOptions options_;
  std::string out_;
  std::unique_ptr<FrameSource> source_;
  HandModel model_;
  std::optional<SequenceSmoother> smoother_;
  OutputFolderLock lock_;                    // held for the whole pass
  std::unique_ptr<OverlayWriter> overlays_;  // output.overlays: the smoothed labels'
  std::string job_hash_;
  std::vector<std::string> ids_;
  std::vector<LabelledFrame> frames_;
  std::vector<std::vector<size_t>> segments_;
  Eigen::VectorXd betas_;
  std::set<std::string> mine_;
  std::set<size_t> written_;
  SmoothSummary summary_;
};

// Per-frame and smoothed keypoints of the labelled frames, with the truth where known.
struct ComparedFrame {
  int64_t number = 0;
  Points3d per_frame, smoothed;
  std::optional<FrameGroundTruth> truth;
};

json MetricsOf(const std::vector<ComparedFrame>& frames, bool smoothed) {
  std::vector<MotionFrame> motion;
  double mpjpe = 0, bones = 0;
  int with_truth = 0;
  for (const ComparedFrame& f : frames) {
    const Points3d& k = smoothed ? f.smoothed : f.per_frame;
    MotionFrame m{f.number, k, Points3d()};
    if (f.truth) {
      m.truth = f.truth->keypoints;
      mpjpe += MeanPointError(k, f.truth->keypoints);
      bones += MeanBoneLengthError(k, f.truth->keypoints);
      ++with_truth;
    }
    motion.push_back(std::move(m));
  }
  const MotionMetrics mm = ComputeMotionMetrics(motion);
  json j = {{"frames", frames.size()},
            {"triples", mm.triples},
            {"jitter_mm", mm.jitter * 1000}};
  if (with_truth > 0) {
    j["mpjpe_mm"] = mpjpe / with_truth * 1000;
    j["bone_length_error_mm"] = bones / with_truth * 1000;
    j["accel_error_mm"] = mm.acceleration_error * 1000;
  }
  return j;
}

// A few lines for the terminal: both groups' metrics and how far smoothing moved.
std::string ReportText(const json& report) {
  std::ostringstream text;
  text << report.at("smoothed").get<int>() << " frames in "
       << report.at("segments").get<int>() << " segments\n";
  for (const char* group : {"per_frame", "smoothed_labels"}) {
    text << "  " << group << ":";
    for (const auto& [key, value] : report.at(group).items()) {
      if (value.is_number_float()) {
        text << " " << key << " " << std::fixed << std::setprecision(3)
             << value.get<double>();
      }
    }
    text << "\n";
  }
  text << "  moved from the per-frame labels: " << std::fixed << std::setprecision(3)
       << report.at("moved_mm").get<double>() << " mm\n";
  return text.str();
}

json SmoothJobRun::Report() const {
  std::vector<ComparedFrame> compared;
  const std::vector<int64_t> numbers = MotionFrameNumbers(ids_);
  bool all_truth = true;
  for (size_t i = 0; i < frames_.size(); ++i) {
    if (!frames_[i].label) continue;
    const std::string path = LabelFilePath(out_, ids_[i]);
    if (!fs::exists(path)) return nullptr;  // not every frame smoothed yet
    ComparedFrame f;
    f.number = numbers[i];
    f.per_frame = frames_[i].label->mesh.keypoints;
    f.smoothed = ReadLabelFile(path).mesh.keypoints;
    f.truth = job_.evaluate ? source_->Load(ids_[i]).ground_truth : std::nullopt;
    all_truth &= f.truth.has_value();
    compared.push_back(std::move(f));
  }
  if (!all_truth) {
    for (ComparedFrame& f : compared) f.truth.reset();
  }
  double moved = 0;
  for (const ComparedFrame& f : compared)
    moved += PointErrors(f.smoothed, f.per_frame).mean();
  json report = {
      {"frames", ids_.size()},
      {"smoothed", compared.size()},
      {"segments", segments_.size()},
      {"window", job_.sequence.window},
      {"overlap", job_.sequence.overlap},
      {"acceleration_sigma_mm", job_.sequence.acceleration_sigma_mm},
      {"detector_keypoints", job_.sequence.detector_keypoints},
      {"betas", std::vector<double>(betas_.data(), betas_.data() + betas_.size())},
      {"moved_mm", moved / compared.size() * 1000},
      {"per_frame", MetricsOf(compared, false)},
      {"smoothed_labels", MetricsOf(compared, true)}};
  WriteFileAtomically((fs::path(out_) / "summary.json").string(), report.dump(1) + "\n");
  return report;
}

}  // namespace

std::vector<WindowSpan> SegmentWindows(int length, int window, int overlap) {
  HL_CHECK(length >= 1 && window >= 3 && overlap >= 1 && 2 * overlap <= window,
           "a segment and a window layout");
  if (length <= window) return {{0, length}};
  std::vector<WindowSpan> spans;
  const int step = window - overlap;
  int begin = 0;
  for (; begin + window < length; begin += step) spans.push_back({begin, begin + window});
  spans.push_back({length - window, length});
  return spans;
}

double BlendWeight(const WindowSpan& span, int i, int length, int overlap) {
  double weight = 1.0;
  const double ramp = overlap + 1.0;
  if (span.begin > 0) weight = std::min(weight, (i - span.begin + 1) / ramp);
  if (span.end < length) weight = std::min(weight, (span.end - i) / ramp);
  return weight;
}

HandParams BlendParams(const std::vector<std::pair<double, HandParams>>& weighted) {
  HL_CHECK(!weighted.empty(), "parameters to blend");
  if (weighted.size() == 1) return weighted[0].second;
  double total = 0;
  for (const auto& [w, p] : weighted) total += w;
  HandParams out = weighted[0].second;
  out.hand_pose.setZero();
  out.transl.setZero();
  out.betas.setZero();
  const Eigen::Quaterniond first =
      QuaternionFromAxisAngle(weighted[0].second.global_orient);
  Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();
  for (const auto& [w, p] : weighted) {
    const double share = w / total;
    Eigen::Quaterniond q = QuaternionFromAxisAngle(p.global_orient);
    if (q.coeffs().dot(first.coeffs()) < 0) q.coeffs() *= -1;  // same hemisphere
    q_sum += share * q.coeffs();
    out.hand_pose += share * p.hand_pose;
    out.transl += share * p.transl;
    out.betas += share * p.betas;
  }
  Eigen::Quaterniond q;
  q.coeffs() = q_sum.normalized();
  out.global_orient = AxisAngleFromQuaternion(q);
  return out;
}

std::string SmoothedOutputDir(const std::string& output_dir) {
  return (fs::path(output_dir) / "smoothed").string();
}

SmoothSummary RunSmoothJob(const JobConfig& job, const SmoothRunOptions& options) {
  return SmoothJobRun(job, options).Run();
}

}  // namespace handlabel
