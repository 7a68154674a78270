#include "pipeline/label_job.h"

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/atomic_file.h"
#include "pipeline/build_info.h"
#include "pipeline/frame_log.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_policy.h"
#include "pipeline/progress.h"
#include "core/sha256.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The frames of one batch as they move through the stages.
struct Batch {
  std::vector<std::string> ids;
  std::vector<std::optional<FrameInput>> inputs;
  std::vector<std::optional<MeshPrediction>> predictions;
  std::vector<std::string> errors;  // non-empty: the frame failed in an earlier stage
  // Non-empty: the network failed on this frame; in fallback mode the fitter takes over.
  std::vector<std::string> network_errors;
  std::vector<double> seconds;
};

std::string Describe(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown error";
  }
}

// A folder holds the outputs of one job: refuse to mix labels of different jobs.
void ClaimOutputFolder(const JobConfig& job, const std::string& job_hash, bool force) {
  const std::string stamp = JobStampPath(job.output_dir);
  if (fs::exists(stamp) && !force) {
    std::ifstream in(stamp);
    std::string recorded;
    try {
      recorded = nlohmann::json::parse(in).at("job_hash").get<std::string>();
    } catch (const std::exception& e) {
      throw InputError(stamp, "job_hash", "a job stamp written by handlabel", e.what());
    }
    if (recorded != job_hash) {
      throw InputError(stamp, "job_hash",
                       "this job's hash " + job_hash +
                           " (the folder holds labels of a different job or job version; "
                           "use another output.dir, or --force to relabel every frame)",
                       recorded);
    }
    return;
  }
  const nlohmann::json j = {
      {"job", job.name}, {"job_hash", job_hash}, {"job_file", job.source_file}};
  WriteFileAtomically(stamp, j.dump(1) + "\n");
}

}  // namespace

std::string JobHash(const JobConfig& job, const std::string& weights_sha256) {
  const QualityThresholds& q = job.quality;
  const nlohmann::json j = {
      {"label_format", kLabelFormatVersion},
      {"input", {job.input_format, job.input_path, job.frames}},
      {"cameras", {job.cameras_source, job.cameras_file}},
      {"hand_model", job.hand_model},
      {"weights_sha256", weights_sha256},
      {"refine",
       {ToString(job.refine_mode), q.max_reprojection_px, q.max_view_disagreement_mm,
        q.min_confidence, q.min_views, q.min_hand_span_m, q.max_hand_span_m}},
      {"evidence", {static_cast<int>(job.keypoints), static_cast<int>(job.masks)}},
      {"seed", job.seed}};
  return Sha256Hex(j.dump());
}

std::vector<std::string> SelectFrames(const std::vector<std::string>& all_frames,
                                      const std::string& spec,
                                      const std::string& source) {
  if (spec == "all" || spec.empty()) return all_frames;
  const size_t colon = spec.find(':');
  if (colon != std::string::npos) {
    size_t begin = 0, end = all_frames.size();
    try {
      if (colon > 0) begin = std::stoul(spec.substr(0, colon));
      if (colon + 1 < spec.size()) end = std::stoul(spec.substr(colon + 1));
    } catch (const std::exception&) {
      throw InputError(source, "input.frames", "'all', 'a:b' or 'id,id,...'",
                       "'" + spec + "'");
    }
    if (begin > end || end > all_frames.size()) {
      throw InputError(
          source, "input.frames",
          "a range within the capture's " + std::to_string(all_frames.size()) + " frames",
          "'" + spec + "'");
    }
    return {all_frames.begin() + begin, all_frames.begin() + end};
  }
  const std::set<std::string> known(all_frames.begin(), all_frames.end());
  std::set<std::string> chosen;
  size_t start = 0;
  while (start <= spec.size()) {
    size_t comma = spec.find(',', start);
    if (comma == std::string::npos) comma = spec.size();
    std::string id = spec.substr(start, comma - start);
    id.erase(0, id.find_first_not_of(' '));
    id.erase(id.find_last_not_of(' ') + 1);
    if (!id.empty()) {
      if (!known.count(id)) {
        throw InputError(source, "input.frames", "frame ids of the capture",
                         "'" + id + "'");
      }
      chosen.insert(id);
    }
    start = comma + 1;
  }
  std::vector<std::string> frames;
  for (const std::string& f : all_frames) {
    if (chosen.count(f)) frames.push_back(f);
  }
  return frames;
}

LabelSummary RunLabelJob(const JobConfig& job, const LabelStageSet& stages,
                         const LabelRunOptions& options) {
  HL_CHECK(stages.source != nullptr, "a frame source");
  HL_CHECK(stages.predictor || job.refine_mode != RefineMode::kOff,
           "a network for refine off");
  const Clock::time_point start = Clock::now();
  const std::string& out = job.output_dir;

  const std::string weights_sha =
      stages.predictor ? stages.predictor->weights_sha256 : "";
  const std::string job_hash = JobHash(job, weights_sha);
  const std::vector<std::string> all_frames =
      SelectFrames(stages.source->FrameIds(), job.frames, job.source_file);
  const std::vector<std::string> mine = FramesOfShard(all_frames, options.shard);
  for (const std::string& f : mine) FrameFileStem(f, stages.source->Describe());

  ClaimOutputFolder(job, job_hash, options.force);
  const std::string log_path = ShardLogPath(out, options.shard);
  if (options.force) fs::remove(log_path);
  RemoveStaleFrameTemporaries(out, mine);

  std::vector<std::string> todo;
  int done_before = 0;
  {
    const auto records =
        options.force ? std::map<std::string, FrameRecord>{} : ReadShardLogs(out);
    for (const std::string& f : mine) {
      const auto it = records.find(f);
      if (it != records.end() && it->second.status == "ok" &&
          fs::exists(LabelFilePath(out, f))) {
        ++done_before;
      } else {
        todo.push_back(f);
      }
    }
  }
  if (done_before > 0 && !options.resume && !options.force) {
    throw InputError(
        job.source_file, "output.dir",
        "a folder without finished frames of this shard, or --resume to skip "
        "them, or --force to label them again",
        std::to_string(done_before) + " finished frame(s) in " + out);
  }

  FrameLog log(log_path);
  const BuildInfo build = GetBuildInfo();
  LabelContext context;
  context.job = &job;
  context.fitter = stages.fitter;
  context.side = stages.side;
  context.provenance = {stages.predictor ? stages.predictor->model_name : "",
                        weights_sha,
                        stages.hand_model_name,
                        job_hash,
                        build.version,
                        build.git_hash,
                        job.seed};

  const int threads = job.threads > 0 ? job.threads : tbb::info::default_concurrency();
  if (options.log) {
    *options.log << "label: job '" << job.name << "', shard " << options.shard.ToString()
                 << ": " << mine.size() << " of " << all_frames.size() << " frames, "
                 << done_before << " done before, " << todo.size() << " to label; "
                 << threads << " thread(s)\n  input: " << stages.source->Describe()
                 << "\n  network: "
                 << (stages.predictor ? stages.predictor->model_name
                                      : std::string("none"))
                 << ", refine: " << ToString(job.refine_mode) << ", fitter: "
                 << (stages.fitter ? stages.fitter->Describe() : std::string("none"))
                 << "\n  output: " << out << "\n";
  }

  std::ostringstream discard;
  Progress progress(static_cast<int>(todo.size()), options.log ? *options.log : discard,
                    options.interactive);

  auto finish_frame = [&](Batch& batch, size_t i) {
    const Clock::time_point frame_start = Clock::now();
    FrameRecord record;
    record.frame = batch.ids[i];
    std::string error = batch.errors[i];
    const std::string& network_error = batch.network_errors[i];
    const bool fit_instead =
        job.refine_mode == RefineMode::kFallback && context.fitter != nullptr;
    if (error.empty() && !network_error.empty() && !fit_instead) error = network_error;
    if (error.empty()) {
      try {
        const FrameInput& frame = *batch.inputs[i];
        const MeshPrediction* prediction =
            batch.predictions[i] ? &*batch.predictions[i] : nullptr;
        FrameOutcome outcome =
            LabelFrame(context, frame, prediction, FrameSeed(job.seed, frame.id));
        if (!network_error.empty()) outcome.label.fit["why"] = network_error;
        if (stages.overlays && job.overlays)
          stages.overlays->Write(out, frame, outcome.label);
        WriteLabelFiles(out, outcome.label, stages.faces, job.meshes);
        record.status = "ok";
        record.path = ToString(outcome.label.path);
        record.metrics = std::move(outcome.metrics);
      } catch (...) {
        error = Describe(std::current_exception());
        if (!network_error.empty()) error = network_error + "; fallback fit: " + error;
      }
    }
    if (!error.empty()) {
      record.status = "failed";
      record.reason = error;
      std::error_code ignored;
      fs::remove(LabelFilePath(out, record.frame),
                 ignored);  // no stale label of a failed frame
    }
    record.seconds = batch.seconds[i] + SecondsSince(frame_start);
    log.Record(record);
    progress.FrameDone(!error.empty());
    batch.inputs[i].reset();  // free the frame's memory early
  };

  const size_t batch_size = static_cast<size_t>(job.batch_size);
  size_t next = 0;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_pipeline(
        static_cast<size_t>(2 * threads),
        tbb::make_filter<void, std::shared_ptr<Batch>>(
            tbb::filter_mode::serial_in_order,
            [&](tbb::flow_control& control) -> std::shared_ptr<Batch> {
              if (next >= todo.size()) {
                control.stop();
                return nullptr;
              }
              auto batch = std::make_shared<Batch>();
              const size_t end = std::min(todo.size(), next + batch_size);
              batch->ids.assign(todo.begin() + next, todo.begin() + end);
              next = end;
              const size_t n = batch->ids.size();
              batch->inputs.resize(n);
              batch->predictions.resize(n);
              batch->errors.resize(n);
              batch->network_errors.resize(n);
              batch->seconds.assign(n, 0.0);
              return batch;
            }) &
            tbb::make_filter<std::shared_ptr<Batch>, std::shared_ptr<Batch>>(
                tbb::filter_mode::parallel,
                [&](std::shared_ptr<Batch> batch) {
                  tbb::parallel_for(size_t(0), batch->ids.size(), [&](size_t i) {
                    const Clock::time_point t = Clock::now();
                    try {
                      batch->inputs[i] = stages.source->Load(batch->ids[i]);
                    } catch (...) {
                      batch->errors[i] = "read: " + Describe(std::current_exception());
                    }
                    batch->seconds[i] += SecondsSince(t);
                  });
                  return batch;
                }) &
            tbb::make_filter<std::shared_ptr<Batch>, std::shared_ptr<Batch>>(
                tbb::filter_mode::serial_out_of_order,
                [&](std::shared_ptr<Batch> batch) {
                  if (!stages.predictor) return batch;
                  std::vector<size_t> ready;
                  std::vector<const FrameInput*> frames;
                  for (size_t i = 0; i < batch->ids.size(); ++i) {
                    if (batch->errors[i].empty()) {
                      ready.push_back(i);
                      frames.push_back(&*batch->inputs[i]);
                    }
                  }
                  if (frames.empty()) return batch;
                  const Clock::time_point t = Clock::now();
                  bool batch_ok = false;
                  try {
                    std::vector<MeshPrediction> predictions =
                        stages.predictor->predict(frames);
                    HL_CHECK(predictions.size() == frames.size(),
                             "one prediction per frame");
                    for (size_t k = 0; k < ready.size(); ++k) {
                      batch->predictions[ready[k]] = std::move(predictions[k]);
                    }
                    batch_ok = true;
                  } catch (...) {
                  }
                  if (!batch_ok) {  // find the bad frame(s): one by one
                    for (size_t k = 0; k < ready.size(); ++k) {
                      try {
                        auto single = stages.predictor->predict({frames[k]});
                        HL_CHECK(single.size() == 1, "one prediction per frame");
                        batch->predictions[ready[k]] = std::move(single[0]);
                      } catch (...) {
                        batch->network_errors[ready[k]] =
                            "network failed: " + Describe(std::current_exception());
                      }
                    }
                  }
                  const double share = SecondsSince(t) / frames.size();
                  for (size_t i : ready) batch->seconds[i] += share;
                  return batch;
                }) &
            tbb::make_filter<std::shared_ptr<Batch>, void>(
                tbb::filter_mode::parallel, [&](std::shared_ptr<Batch> batch) {
                  tbb::parallel_for(size_t(0), batch->ids.size(),
                                    [&](size_t i) { finish_frame(*batch, i); });
                }));
  });
  progress.Finish();

  LabelSummary summary = Summarize(mine, ReadShardLogs(out));
  summary.skipped = done_before;
  summary.wall_seconds = SecondsSince(start);
  WriteFileAtomically(ShardSummaryPath(out, options.shard),
                      summary.ToJson().dump(1) + "\n");
  if (options.shard.count == 1) MergeLabelOutputs(out, job.name, job_hash, all_frames);
  if (options.log) {
    *options.log << summary.ToText();
    if (options.shard.count == 1) {
      *options.log << "labels in " << out << "/labels, manifest " << ManifestPath(out)
                   << "\n";
    } else {
      *options.log << "shard log " << log_path
                   << "; join shards with: handlabel merge --job " << job.source_file
                   << "\n";
    }
  }
  return summary;
}

}  // namespace handlabel
