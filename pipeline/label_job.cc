#include "pipeline/label_job.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <sstream>

#include "capture/frame_images.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/progress.h"
#include "core/stage_times.h"
#include "core/stopwatch.h"
#include "formats/sha256.h"
#include "pipeline/build_info.h"
#include "pipeline/frame_log.h"
#include "pipeline/frame_metrics.h"
#include "pipeline/job_stamp.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_policy.h"
#include "pipeline/output_lock.h"
#include "pipeline/quality_checks.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The frames of one batch as they move through the stages.
struct Batch {
  size_t index = 0;  // in hand-out order: picks the network lane
  std::vector<std::string> ids;
  std::vector<std::optional<FrameInput>> inputs;
  std::vector<std::optional<MeshPrediction>> predictions;
  std::vector<std::string> errors;  // non-empty: the frame failed in an earlier stage
  // Non-empty: the network failed on this frame; in fallback mode the fitter takes over.
  std::vector<std::string> network_errors;
  // Wall seconds per stage spent on each frame so far (FrameRecord::stages).
  std::vector<StageSeconds> stages;
  // Jobs that track the hand: where the network's crops came from (FrameRecord::crops).
  std::vector<std::string> crops;
};

std::shared_ptr<Batch> MakeBatch(size_t index, std::vector<std::string> ids) {
  auto batch = std::make_shared<Batch>();
  batch->index = index;
  batch->ids = std::move(ids);
  const size_t n = batch->ids.size();
  batch->inputs.resize(n);
  batch->predictions.resize(n);
  batch->errors.resize(n);
  batch->network_errors.resize(n);
  batch->stages.resize(n);
  batch->crops.resize(n);
  return batch;
}

std::string Describe(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown error";
  }
}

// One run of one shard of a job: plan (frames, resume, folder), label every frame to
// do through the stages, then summarise and, for a whole-job run, merge.
// Reading order: Run -> Plan / FindFramesToDo; the per-frame steps Load, Predict,
// FinishFrame (-> WriteFrame); then one scheduler per kind of job, each driving those
// steps: LabelPipelined (the default: batches through a TBB pipeline with the
// network's lanes), LabelInOrder (fit.init previous), LabelVideo / LabelVideoRuns
// (evidence.detector_mode: video), LabelTracked (evidence.detector_every > 1); the
// runs of consecutive frames the last two share (RunsOfFramesToDo); Finish.
class LabelJobRun {
 public:
  LabelJobRun(const JobConfig& job, const LabelStageSet& stages,
              const LabelRunOptions& options)
      : job_(job), stages_(stages), options_(options), out_(job.output_dir) {
    HL_CHECK(stages.source != nullptr, "a frame source");
    HL_CHECK(stages.predictor || job.refine_mode != RefineMode::kOff,
             "a network for refine off");
  }

  LabelSummary Run() {
    const Clock::time_point start = Clock::now();
    Plan();
    FindFramesToDo();
    FrameLog log(log_path_);
    log_ = &log;
    threads_ = job_.threads > 0 ? job_.threads : tbb::info::default_concurrency();
    // fit.init previous: each fit starts from the previous frame's label.
    in_order_ = job_.fit.init == "previous";
    LogStart();
    std::ostringstream discard;
    Progress progress(static_cast<int>(todo_.size()),
                      options_.log ? *options_.log : discard, options_.interactive);
    progress_ = &progress;
    if (stages_.start_video_track) {
      LabelVideo();
    } else if (stages_.find_keypoints_2d) {
      LabelTracked();
    } else if (in_order_) {
      LabelInOrder();
    } else {
      LabelPipelined();
    }
    progress.Finish();
    return Finish(SecondsSince(start));
  }

 private:
  // The job's frames, this shard's part of them, the job hash and the claim on the
  // output folder.
  void Plan() {
    weights_sha_ = stages_.predictor ? stages_.predictor->weights_sha256 : "";
    job_hash_ = JobHash(job_, weights_sha_);
    all_frames_ = JobFrames(job_, *stages_.source);
    mine_ = FramesOfShard(all_frames_, options_.shard);
    shard_begin_ = mine_.empty()
                       ? 0
                       : std::find(all_frames_.begin(), all_frames_.end(), mine_[0]) -
                             all_frames_.begin();
    for (const std::string& f : mine_) FrameFileStem(f, stages_.source->Describe());
    lock_ = OutputFolderLock::ForShard(out_, options_.shard, job_.source_file);
    ClaimOutputFolder(job_, job_hash_, options_.force, &lock_);
    log_path_ = ShardLogPath(out_, options_.shard);
    if (options_.force) fs::remove(log_path_);
    RemoveStaleFrameTemporaries(out_, mine_);
    const BuildInfo build = GetBuildInfo();
    context_.job = &job_;
    context_.fitter = stages_.fitter;
    context_.side = stages_.side;
    context_.provenance = {stages_.predictor ? stages_.predictor->model_name : "",
                           weights_sha_,
                           stages_.hand_model_name,
                           job_hash_,
                           build.version,
                           build.git_hash,
                           job_.seed};
  }

  // Resume: frames with an ok record and their label on disk are done.
  void FindFramesToDo() {
    const auto records =
        options_.force ? std::map<std::string, FrameRecord>{} : ReadShardLogs(out_);
    for (const std::string& f : mine_) {
      const auto it = records.find(f);
      // Done: an ok record of this job whose label is still the file it wrote.
      if (it != records.end() && it->second.status == "ok" &&
          (it->second.job_hash.empty() || it->second.job_hash == job_hash_) &&
          LabelFileProblem(it->second, LabelFilePath(out_, f)).empty()) {
        ++done_before_;
      } else {
        todo_.push_back(f);
      }
    }
    if (done_before_ > 0 && !options_.resume && !options_.force) {
      throw InputError(
          job_.source_file, "output.dir",
          "a folder without finished frames of this shard, or --resume to skip "
          "them, or --force to label them again",
          std::to_string(done_before_) + " finished frame(s) in " + out_);
    }
  }

  void LogStart() const {
    if (!options_.log) return;
    *options_.log << "label: job '" << job_.name << "', shard "
                  << options_.shard.ToString() << ": " << mine_.size() << " of "
                  << all_frames_.size() << " frames, " << done_before_ << " done before, "
                  << todo_.size() << " to label; " << (in_order_ ? 1 : threads_)
                  << " thread(s)"
                  << (in_order_ ? " (fit.init previous: frames in order)" : "")
                  << "\n  input: " << stages_.source->Describe()
                  << "\n  network: " << NetworkText()
                  << ", refine: " << ToString(job_.refine_mode) << ", fitter: "
                  << (stages_.fitter ? stages_.fitter->Describe() : std::string("none"))
                  << "\n  output: " << out_ << "\n";
  }

  // The network's name and how it runs: "poem (w.pt), batches of 4, 2 at once on 1
  // thread each".
  std::string NetworkText() const {
    const NetworkStage* n = stages_.predictor;
    if (!n) return "none";
    std::ostringstream s;
    s << n->model_name << ", batches of " << job_.batch_size;
    const int lanes = in_order_ ? 1 : n->lanes;
    if (lanes > 1) s << ", " << lanes << " at once";
    if (n->threads_per_batch > 0) {
      s << " on " << n->threads_per_batch << " thread"
        << (n->threads_per_batch == 1 ? "" : "s") << (lanes > 1 ? " each" : "");
    }
    if (!n->keypoints.empty()) s << ", keypoints: " << n->keypoints;
    if (!n->precision.empty()) s << ", precision " << n->precision;
    return s.str();
  }

  // The next batch of frames to do (serial), or nullptr when all are handed out.
  std::shared_ptr<Batch> NextBatch(size_t size) {
    if (next_ >= todo_.size()) return nullptr;
    const size_t end = std::min(todo_.size(), next_ + size);
    std::vector<std::string> ids(todo_.begin() + next_, todo_.begin() + end);
    next_ = end;
    return MakeBatch(batches_++, std::move(ids));
  }

  // Reads one frame of the batch; a read error fails that frame only.
  void Load(Batch& batch, size_t i) const {
    const Clock::time_point t = Clock::now();
    try {
      batch.inputs[i] = stages_.source->Load(batch.ids[i]);
      if (stages_.predictor || (stages_.overlays && job_.overlays)) {
        DecodeImages(&*batch.inputs[i]);
      }
    } catch (...) {
      batch.errors[i] = "read: " + Describe(std::current_exception());
    }
    AddStageTime(batch, i, "read", t);
  }

  // The wall time since `start` of a step on frame i: the parts the step timed itself
  // (FrameInput::stage_seconds, e.g. the detector's models inside a reader) under their
  // own names, the rest under `stage`.
  static void AddStageTime(Batch& batch, size_t i, const std::string& stage,
                           Clock::time_point start) {
    const double seconds = SecondsSince(start);
    double parts = 0;
    if (batch.inputs[i]) {
      StageSeconds& reported = batch.inputs[i]->stage_seconds;
      parts = TotalStageSeconds(reported);
      AddStageSeconds(reported, &batch.stages[i]);
      reported.clear();
    }
    batch.stages[i][stage] += std::max(0.0, seconds - parts);
  }

  // The frame's images, decoded here (in parallel) once for the network, whose stage
  // is serial, and the overlays. A bad image file is left to the stage that needs it:
  // the network's failure falls back to fitting, the overlay's fails the frame.
  static void DecodeImages(FrameInput* frame) {
    try {
      DecodeFrameImages(frame);
    } catch (const InputError&) {
      frame->images.clear();
    }
  }

  // The network on the batch's readable frames (one caller at a time). If the batch
  // fails, the frames run one by one so that a bad frame fails alone.
  void Predict(Batch& batch) const {
    if (!stages_.predictor) return;
    std::vector<size_t> ready;
    std::vector<const FrameInput*> frames;
    for (size_t i = 0; i < batch.ids.size(); ++i) {
      if (batch.errors[i].empty()) {
        ready.push_back(i);
        frames.push_back(&*batch.inputs[i]);
      }
    }
    if (frames.empty()) return;
    const Clock::time_point t = Clock::now();
    try {
      std::vector<MeshPrediction> predictions = stages_.predictor->predict(frames);
      HL_CHECK(predictions.size() == frames.size(), "one prediction per frame");
      for (size_t k = 0; k < ready.size(); ++k) {
        batch.predictions[ready[k]] = std::move(predictions[k]);
      }
    } catch (...) {
      for (size_t k = 0; k < ready.size(); ++k) {
        try {
          auto single = stages_.predictor->predict({frames[k]});
          HL_CHECK(single.size() == 1, "one prediction per frame");
          batch.predictions[ready[k]] = std::move(single[0]);
        } catch (...) {
          batch.network_errors[ready[k]] =
              "network failed: " + Describe(std::current_exception());
        }
      }
    }
    const double share = SecondsSince(t) / frames.size();
    for (size_t i : ready) batch.stages[i]["network"] += share;
  }

  // fit.init previous: the label parameters of the frame before `frame` in the job's
  // frame order, when its label is on disk (written by this run or an earlier one).
  std::optional<HandParams> PreviousParams(const std::string& frame) const {
    if (!in_order_) return std::nullopt;
    const auto it = std::find(all_frames_.begin(), all_frames_.end(), frame);
    if (it == all_frames_.begin() || it == all_frames_.end()) return std::nullopt;
    const std::string path = LabelFilePath(out_, *(it - 1));
    if (!fs::exists(path)) return std::nullopt;
    return ReadLabelFile(path).params;
  }

  // Labels one frame (policy, outputs) and records it in the shard log.
  void FinishFrame(Batch& batch, size_t i) {
    const Clock::time_point frame_start = Clock::now();
    const double before = TotalStageSeconds(batch.stages[i]);
    FrameRecord record;
    record.frame = batch.ids[i];
    std::string error = batch.errors[i];
    const std::string& network_error = batch.network_errors[i];
    const bool fit_instead =
        job_.refine_mode == RefineMode::kFallback && context_.fitter != nullptr;
    if (error.empty() && !network_error.empty() && !fit_instead) error = network_error;
    if (error.empty()) {
      try {
        WriteFrame(batch, i, &record);
      } catch (...) {
        error = Describe(std::current_exception());
        if (!network_error.empty()) error = network_error + "; fallback fit: " + error;
      }
    }
    StageSeconds& stages = batch.stages[i];
    if (stages_.write_detections && batch.inputs[i]) {
      try {  // before the record: a finished frame has its detections file
        StageTimer timer(&stages, "write.detections");
        stages_.write_detections(out_, *batch.inputs[i]);
      } catch (...) {
        if (error.empty())
          error = "detections file: " + Describe(std::current_exception());
      }
    }
    if (!error.empty()) {
      record.status = "failed";
      record.reason = error;
      std::error_code ignored;  // no stale label of a failed frame
      fs::remove(LabelFilePath(out_, record.frame), ignored);
    }
    record.job_hash = job_hash_;
    if (error.empty()) {  // what resume and merge check the file against
      StageTimer timer(&stages, "write.checksum");
      const std::string label = LabelFilePath(out_, record.frame);
      record.label_bytes = static_cast<int64_t>(fs::file_size(label));
      record.label_sha256 = Sha256OfFile(label);
    }
    const double finish = SecondsSince(frame_start);
    // What this step did outside its timed stages: the label policy's choices,
    // fit.init previous's read of the previous label, the record.
    stages["other"] += std::max(0.0, finish - (TotalStageSeconds(stages) - before));
    record.seconds = TotalStageSeconds(stages);
    record.stages = stages;
    record.crops = batch.crops[i];
    if (batch.inputs[i]) record.hand = batch.inputs[i]->evidence_hand;
    log_->Record(record);
    progress_->FrameDone(!error.empty());
    batch.inputs[i].reset();  // free the frame's memory early
  }

  void WriteFrame(Batch& batch, size_t i, FrameRecord* record) const {
    const FrameInput& frame = *batch.inputs[i];
    const MeshPrediction* prediction =
        batch.predictions[i] ? &*batch.predictions[i] : nullptr;
    const std::optional<HandParams> previous = PreviousParams(frame.id);
    FrameOutcome outcome =
        LabelFrame(context_, frame, prediction, FrameSeed(job_.seed, frame.id),
                   previous ? &*previous : nullptr);
    StageSeconds& stages = batch.stages[i];
    AddStageSeconds(outcome.stage_seconds, &stages);
    if (!batch.network_errors[i].empty()) {
      outcome.label.fit["why"] = batch.network_errors[i];
    }
    if (stages_.overlays && job_.overlays) {
      StageTimer timer(&stages, "write.overlays");
      stages_.overlays->Write(out_, frame, outcome.label);
    }
    {
      StageTimer timer(&stages, "write.labels");
      WriteLabelFiles(out_, outcome.label, stages_.faces, job_.meshes);
    }
    record->status = "ok";
    record->path = ToString(outcome.label.path);
    record->metrics = std::move(outcome.metrics);
    for (const auto& [group, keypoints] : outcome.keypoints) {
      record->keypoints_mm[group] = KeypointsToMillimetres(keypoints);
    }
  }

  // The network stage as `lanes` serial filters in a row; lane k predicts the batches
  // whose index is k modulo lanes and passes the others on: at most `lanes` batches in
  // the network at once, without blocking a worker thread.
  static tbb::filter<std::shared_ptr<Batch>, std::shared_ptr<Batch>> NetworkLanes(
      int lanes, const std::function<void(Batch&)>& predict) {
    using BatchPtr = std::shared_ptr<Batch>;
    auto lane = [&predict, lanes](int k) {
      return tbb::make_filter<BatchPtr, BatchPtr>(
          tbb::filter_mode::serial_out_of_order, [&predict, lanes, k](BatchPtr batch) {
            if (batch->index % lanes == static_cast<size_t>(k)) predict(*batch);
            return batch;
          });
    };
    tbb::filter<BatchPtr, BatchPtr> all = lane(0);
    for (int k = 1; k < lanes; ++k) all = all & lane(k);
    return all;
  }

  // TBB stages over batches: hand out (serial), read (parallel), network (serial per
  // lane, batched), label and write (parallel).
  void LabelPipelined() {
    using BatchPtr = std::shared_ptr<Batch>;
    const size_t batch_size = static_cast<size_t>(job_.batch_size);
    const int lanes = stages_.predictor ? std::max(1, stages_.predictor->lanes) : 1;
    const std::function<void(Batch&)> predict = [this](Batch& b) { Predict(b); };
    tbb::task_arena arena(threads_);
    arena.execute([&] {
      tbb::parallel_pipeline(
          static_cast<size_t>(2 * threads_),
          HandOutBatches(batch_size) &
              tbb::make_filter<BatchPtr, BatchPtr>(
                  tbb::filter_mode::parallel,
                  [&](BatchPtr batch) {
                    tbb::parallel_for(size_t(0), batch->ids.size(),
                                      [&](size_t i) { Load(*batch, i); });
                    return batch;
                  }) &
              NetworkLanes(lanes, predict) &
              tbb::make_filter<BatchPtr, void>(
                  tbb::filter_mode::parallel, [&](BatchPtr batch) {
                    tbb::parallel_for(size_t(0), batch->ids.size(),
                                      [&](size_t i) { FinishFrame(*batch, i); });
                  }));
    });
  }

  // The first filter of a job's pipeline: the frames to do in batches of `size`, in
  // the job's frame order (serial), until none is left.
  tbb::filter<void, std::shared_ptr<Batch>> HandOutBatches(size_t size) {
    return tbb::make_filter<void, std::shared_ptr<Batch>>(
        tbb::filter_mode::serial_in_order, [this, size](tbb::flow_control& control) {
          std::shared_ptr<Batch> batch = NextBatch(size);
          if (!batch) control.stop();
          return batch;
        });
  }

  // The same steps one frame at a time, in the job's frame order.
  void LabelInOrder() {
    while (const std::shared_ptr<Batch> batch = NextBatch(1)) {
      Load(*batch, 0);
      Predict(*batch);
      FinishFrame(*batch, 0);
    }
  }

  // Video mode (evidence.detector_mode: video): hand out frames (serial), read
  // (parallel), detect (serial, in order: each frame from the previous one's answer),
  // the network if any (one frame at a time), label and write (parallel; in order
  // with fit.init previous).
  void LabelVideo() {
    if (!in_order_ && !stages_.predictor) {
      LabelVideoRuns();
      return;
    }
    using BatchPtr = std::shared_ptr<Batch>;
    for (size_t i = 0; i < mine_.size(); ++i) position_[mine_[i]] = i;
    const tbb::filter_mode finish =
        in_order_ ? tbb::filter_mode::serial_in_order : tbb::filter_mode::parallel;
    tbb::task_arena arena(threads_);
    arena.execute([&] {
      tbb::parallel_pipeline(
          static_cast<size_t>(2 * threads_),
          HandOutBatches(1) &
              tbb::make_filter<BatchPtr, BatchPtr>(tbb::filter_mode::parallel,
                                                   [&](BatchPtr batch) {
                                                     Load(*batch, 0);
                                                     return batch;
                                                   }) &
              tbb::make_filter<BatchPtr, BatchPtr>(tbb::filter_mode::serial_in_order,
                                                   [&](BatchPtr batch) {
                                                     DetectInVideo(*batch);
                                                     return batch;
                                                   }) &
              tbb::make_filter<BatchPtr, BatchPtr>(tbb::filter_mode::serial_out_of_order,
                                                   [&](BatchPtr batch) {
                                                     Predict(*batch);
                                                     return batch;
                                                   }) &
              tbb::make_filter<BatchPtr, void>(
                  finish, [&](BatchPtr batch) { FinishFrame(*batch, 0); }));
    });
  }

  // One frame of video mode, in the shard's frame order. A frame that failed to read
  // breaks the run: the next one starts a new run.
  void DetectInVideo(Batch& batch) {
    const size_t i = position_.at(batch.ids[0]);
    const bool follows = video_last_ + 1 == i && video_last_ != kNoFrame;
    const size_t every = static_cast<size_t>(job_.detector_palm_every);
    const bool starts_run = !follows || (every > 0 && (shard_begin_ + i) % every == 0);
    video_last_ = kNoFrame;
    if (!batch.errors[0].empty()) return;
    const Clock::time_point t = Clock::now();
    try {
      if (starts_run) video_track_ = stages_.start_video_track();
      video_track_(&*batch.inputs[0]);
      video_last_ = i;
    } catch (...) {
      batch.errors[0] = "detect: " + Describe(std::current_exception());
    }
    AddStageTime(batch, 0, "detect.other", t);
  }

  // Video mode without a network or fit.init previous: the runs (VideoRuns) in
  // parallel, each on its own track, as `detect --video` does; a frame is fitted and
  // written as soon as it is detected.
  void LabelVideoRuns() {
    LabelRunsInParallel(VideoRuns(), threads_,
                        [this](const std::vector<size_t>& run) { LabelVideoRun(run); });
  }

  // `label_run` on every run, `threads` runs at once; one run per task, so that a long
  // run does not hold back the runs queued behind it.
  template <typename LabelRun>
  static void LabelRunsInParallel(const std::vector<std::vector<size_t>>& runs,
                                  int threads, LabelRun label_run) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<size_t>(0, runs.size(), 1),
          [&](const tbb::blocked_range<size_t>& r) {
            for (size_t k = r.begin(); k != r.end(); ++k) label_run(runs[k]);
          },
          tbb::simple_partitioner());
    });
  }

  // One run of video mode. A frame that fails to read or to detect breaks the run: the
  // next one starts a new track, as in DetectInVideo.
  void LabelVideoRun(const std::vector<size_t>& run) {
    std::function<void(FrameInput*)> track = stages_.start_video_track();
    for (const size_t i : run) {
      std::shared_ptr<Batch> batch = MakeBatch(0, {mine_[i]});
      Load(*batch, 0);
      if (batch->errors[0].empty()) {
        const Clock::time_point t = Clock::now();
        try {
          track(&*batch->inputs[0]);
        } catch (...) {
          batch->errors[0] = "detect: " + Describe(std::current_exception());
        }
        AddStageTime(*batch, 0, "detect.other", t);
      }
      if (!batch->errors[0].empty()) track = stages_.start_video_track();
      FinishFrame(*batch, 0);
    }
  }

  // The shard's frames to do (positions in mine_) in video-mode runs: a run starts at
  // the first frame to do, after a gap and at every detector_palm_every-th frame of the
  // job (positions in the job's frame order: shards and resumed runs choose the same).
  std::vector<std::vector<size_t>> VideoRuns() const {
    const size_t every = static_cast<size_t>(job_.detector_palm_every);
    return RunsOfFramesToDo(
        [&](size_t i) { return every > 0 && (shard_begin_ + i) % every == 0; });
  }

  // The shard's frames to do (positions in mine_) in runs of consecutive frames: a run
  // starts at the first frame to do, after a gap and where `starts_run(i)`.
  template <typename StartsRun>
  std::vector<std::vector<size_t>> RunsOfFramesToDo(StartsRun starts_run) const {
    std::vector<std::vector<size_t>> runs;
    size_t t = 0;
    for (size_t i = 0; i < mine_.size() && t < todo_.size(); ++i) {
      if (mine_[i] != todo_[t]) continue;
      ++t;
      if (runs.empty() || runs.back().back() != i - 1 || starts_run(i))
        runs.emplace_back();
      runs.back().push_back(i);
    }
    return runs;
  }

  // A job that tracks the hand (evidence.detector_every): runs of frames in order, each
  // frame's crops from the previous frame's label; runs in parallel, one per network
  // lane (in order with fit.init previous).
  void LabelTracked() {
    const std::vector<std::vector<size_t>> runs = TrackRuns();
    auto label_run = [this](const std::vector<size_t>& run) {
      for (const size_t i : run) LabelTrackedFrame(i);
    };
    if (in_order_) {
      for (const auto& run : runs) label_run(run);
      return;
    }
    LabelRunsInParallel(runs, std::max(1, stages_.predictor->lanes), label_run);
  }

  // The shard's frames to do (positions in mine_) in runs that depend on nothing
  // another run labels: a run starts at a frame the detector runs on anyway
  // (TrackPrior) or after a gap (its prior then is a label of an earlier run).
  std::vector<std::vector<size_t>> TrackRuns() const {
    return RunsOfFramesToDo([&](size_t i) { return IsTrackAnchor(i); });
  }

  // The detector runs on every N-th frame of the job (positions in the job's frame
  // order, so that shards and resumed runs choose the same frames) and on the shard's
  // first frame.
  bool IsTrackAnchor(size_t i) const {
    return i == 0 || (shard_begin_ + i) % static_cast<size_t>(job_.detector_every) == 0;
  }

  // Where frame mine_[i] is expected: the previous frame's label keypoints moved on by
  // their last step (the hand keeps its speed over one frame); labels are read from
  // their files, written by this run or an earlier one, so a resumed job crops as an
  // uninterrupted one. None at an anchor or when the previous frame has no label.
  std::optional<Points3d> TrackPrior(size_t i) const {
    if (IsTrackAnchor(i)) return std::nullopt;
    const std::optional<Points3d> last = LabelKeypoints(mine_[i - 1]);
    if (!last || IsTrackAnchor(i - 1)) return last;
    const std::optional<Points3d> before = LabelKeypoints(mine_[i - 2]);
    if (!before) return last;
    return Points3d(2 * *last - *before);
  }

  std::optional<Points3d> LabelKeypoints(const std::string& frame) const {
    const std::string path = LabelFilePath(out_, frame);
    if (!fs::exists(path)) return std::nullopt;
    try {
      return ReadLabelFile(path).mesh.keypoints;
    } catch (const std::exception&) {
      return std::nullopt;  // an unreadable label: no prior from it
    }
  }

  // One frame of a tracked job: the network on crops around the previous frame's
  // label; if that answer fails its checks (or there is no prior), the frame is
  // detected and labelled as a job that detects every frame labels it.
  void LabelTrackedFrame(size_t i) {
    std::shared_ptr<Batch> batch = MakeBatch(0, {mine_[i]});
    Load(*batch, 0);
    const std::optional<Points3d> prior = TrackPrior(i);
    if (prior && batch->errors[0].empty()) {
      batch->inputs[0]->crop_prior = *prior;
      Predict(*batch);
      if (TrackedAnswerPasses(*batch)) {
        batch->crops[0] = "previous_label";
        FinishFrame(*batch, 0);
        return;
      }
      batch->inputs[0]->crop_prior = Points3d();
      batch->predictions[0].reset();
      batch->network_errors[0].clear();
    }
    FindKeypoints2d(*batch);
    Predict(*batch);
    batch->crops[0] = "detector";
    FinishFrame(*batch, 0);
  }

  // The quality checks of a tracked frame's answer (no file 2D to judge it against).
  bool TrackedAnswerPasses(const Batch& batch) const {
    if (!batch.predictions[0]) return false;
    return CheckPrediction(batch.inputs[0]->rig, *batch.predictions[0], job_.quality)
        .Passed();
  }

  void FindKeypoints2d(Batch& batch) const {
    if (!batch.errors[0].empty()) return;
    const Clock::time_point t = Clock::now();
    try {
      stages_.find_keypoints_2d(&*batch.inputs[0]);
    } catch (...) {
      batch.errors[0] = "detect: " + Describe(std::current_exception());
    }
    AddStageTime(batch, 0, "detect.other", t);
  }

  // What the job's 2D keypoints are: the capture's (or evidence.detections'), the
  // network's, or both (evidence.keypoints_2d).
  std::string KeypointsSourceText() const {
    const std::string files = stages_.source->KeypointsSource();
    const std::string own = stages_.predictor ? "the network's own 2D" : "";
    if (job_.keypoints == KeypointSource::kNetwork) return own;
    if (job_.keypoints == KeypointSource::kFiles && stages_.find_keypoints_2d) {
      return files + ", run on 1 frame in " + std::to_string(job_.detector_every) +
             " and where the network's answer from crops around the previous frame's "
             "label fails its checks";
    }
    if (job_.keypoints == KeypointSource::kFiles) return files.empty() ? "none" : files;
    return files.empty() ? own : files + ", else " + own;
  }

  // The shard's summary file, the merge of a whole-job run, the closing lines.
  LabelSummary Finish(double wall_seconds) const {
    LabelSummary summary = Summarize(mine_, ReadShardLogs(out_));
    summary.keypoints_2d_source = KeypointsSourceText();
    summary.skipped = done_before_;
    summary.wall_seconds = wall_seconds;
    summary.threads = in_order_ ? 1 : threads_;
    WriteFileAtomically(ShardSummaryPath(out_, options_.shard),
                        summary.ToJson().dump(1) + "\n");
    const bool whole_job = options_.shard.count == 1;
    if (whole_job) {
      MergeLabelOutputs(out_, job_.name, job_hash_, all_frames_,
                        summary.keypoints_2d_source, nullptr, &summary);
    }
    if (!options_.log) return summary;
    *options_.log << summary.ToText();
    if (whole_job) {
      *options_.log << "labels in " << out_ << "/labels, manifest " << ManifestPath(out_)
                    << "\n";
    } else {
      *options_.log << "shard log " << log_path_
                    << "; join shards with: handlabel merge --job " << job_.source_file
                    << "\n";
    }
    return summary;
  }

  const JobConfig& job_;
  const LabelStageSet& stages_;
  const LabelRunOptions& options_;
  const std::string out_;
  std::string weights_sha_, job_hash_, log_path_;
  std::vector<std::string> all_frames_, mine_, todo_;
  size_t shard_begin_ = 0;  // position of the shard's first frame in all_frames_
  // Video mode: positions of the shard's frames in mine_, and the last frame detected
  // (kNoFrame: none, or the last one failed).
  static constexpr size_t kNoFrame = static_cast<size_t>(-1);
  std::map<std::string, size_t> position_;
  size_t video_last_ = kNoFrame;
  std::function<void(FrameInput*)> video_track_;  // the run's track (DetectInVideo)
  int done_before_ = 0;
  int threads_ = 1;
  bool in_order_ = false;
  size_t next_ = 0;     // next frame of todo_ to hand out
  size_t batches_ = 0;  // batches handed out
  LabelContext context_;
  OutputFolderLock lock_;  // held for the whole run
  FrameLog* log_ = nullptr;
  Progress* progress_ = nullptr;
};

}  // namespace

LabelSummary RunLabelJob(const JobConfig& job, const LabelStageSet& stages,
                         const LabelRunOptions& options) {
  return LabelJobRun(job, stages, options).Run();
}

}  // namespace handlabel
