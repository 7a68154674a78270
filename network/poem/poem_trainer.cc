#include "network/poem/poem_trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/file_lock.h"
#include "core/json_util.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "hand/metrics.h"
#include "network/poem/poem_batch_norm_update.h"
#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_training_batch.h"

namespace handlabel {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// latest.json of a training folder, checked: a corrupt or hand-edited file names the
// file and field instead of surfacing as a raw JSON exception.
struct LatestCheckpoint {
  int64_t step = 0;
  std::string model, optimizer;  // relative to the training folder
  // What a resume must keep: seed, batch_size and (when recorded) data.
  nlohmann::json settings = nlohmann::json::object();
};

LatestCheckpoint ReadLatestJson(const std::string& path) {
  const nlohmann::json j = ReadJsonFileStrict(path);
  RejectUnknownKeys(
      j, {"step", "model", "optimizer", "config", "seed", "batch_size", "steps", "data"},
      path);
  const nlohmann::json& step = JsonMember(j, "step", path);
  if (!step.is_number_integer() || step.get<int64_t>() < 0) {
    throw InputError(path, "step", "a non-negative integer", step.dump());
  }
  LatestCheckpoint latest{step.get<int64_t>(), JsonString(j, "model", path),
                          JsonString(j, "optimizer", path)};
  for (const char* key : {"seed", "batch_size", "data"}) {
    if (j.contains(key)) latest.settings[key] = j[key];
  }
  return latest;
}

// The settings of a run that a resume must keep, as latest.json records them.
nlohmann::json ResumeSettings(const PoemTrainerOptions& o) {
  nlohmann::json settings = {{"seed", o.seed}, {"batch_size", o.batch_size}};
  if (!o.data_settings.empty()) settings["data"] = o.data_settings;
  return settings;
}

// "/data/synth/seed" (a flattened JSON key) -> "data.synth.seed".
std::string SettingName(const std::string& pointer) {
  std::string name = pointer.substr(1);
  std::replace(name.begin(), name.end(), '/', '.');
  return name;
}

// Throws InputError naming the first setting (e.g. data.synth.seed) whose recorded
// value differs from this run's. Settings latest.json does not record (a run written
// before they were), and data when this run gives none, are not checked.
void CheckResumeSettings(const nlohmann::json& recorded, const nlohmann::json& now,
                         const std::string& path) {
  const nlohmann::json was = recorded.flatten(), is = now.flatten();
  const auto is_data = [](const std::string& key) { return key.rfind("/data/", 0) == 0; };
  for (const auto& [key, value] : was.items()) {
    if (is_data(key) && !now.contains("data")) continue;
    const auto it = is.find(key);
    if (it != is.end() && *it == value) continue;
    throw InputError(path, SettingName(key),
                     "the value the run began with, " + value.dump() +
                         " (--resume continues a run on the data and batches it "
                         "began with; train into a new folder for other settings)",
                     it == is.end() ? "nothing" : it->dump());
  }
  if (!recorded.contains("data")) return;
  for (const auto& [key, value] : is.items()) {
    if (is_data(key) && !was.contains(key)) {
      throw InputError(path, SettingName(key),
                       "no value (the run began without this setting)", value.dump());
    }
  }
}

std::string StepName(int64_t step) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "step_%08lld", static_cast<long long>(step));
  return buf;
}

std::string Duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long long s = std::llround(seconds);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof(buf), "%lldh%02lldm", s / 3600, (s / 60) % 60);
  else
    std::snprintf(buf, sizeof(buf), "%lldm%02llds", s / 60, s % 60);
  return buf;
}

// Keeps the header and the rows whose first field (a step) is <= `step`: rows logged
// after the checkpoint a killed run is resumed from would otherwise appear twice.
void TruncateCsv(const std::string& path, int64_t step) {
  if (!fs::exists(path)) return;
  std::istringstream in(ReadText(path));
  std::string line, out;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (header || std::stoll(line.substr(0, line.find(','))) <= step) out += line + "\n";
    header = false;
  }
  WriteFileAtomically(path, out);
}

void AppendLine(const std::string& path, const std::string& header,
                const std::string& line) {
  const bool fresh = !fs::exists(path) || fs::file_size(path) == 0;
  std::ofstream out(path, std::ios::app);
  if (fresh) out << header << "\n";
  out << line << "\n";
  if (!out) throw Error("cannot append to " + path);
}

// When training started and how many steps ran since the last log line.
struct StepClock {
  Clock::time_point start = Clock::now();
  Clock::time_point window_start = start;
  int64_t window_steps = 0;
};

// Makes the batches of steps [first, last) on a background thread, in order.
class BatchProducer {
 public:
  BatchProducer(const TrainingSampleSource& source, int batch_size, int64_t first,
                int64_t last, int depth)
      : source_(source),
        batch_size_(batch_size),
        next_(first),
        last_(last),
        depth_(depth) {
    if (depth_ > 0) thread_ = std::thread([this] { Loop(); });
  }
  ~BatchProducer() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  std::vector<TrainingSample> Next() {
    if (depth_ == 0) return Make(next_++);
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return !queue_.empty() || error_; });
    if (queue_.empty()) std::rethrow_exception(error_);
    std::vector<TrainingSample> batch = std::move(queue_.front());
    queue_.pop_front();
    cv_.notify_all();
    return batch;
  }

 private:
  std::vector<TrainingSample> Make(int64_t step) const {
    return SampleRange(source_, step * batch_size_, (step + 1) * batch_size_);
  }
  void Loop() {
    try {
      for (int64_t step = next_; step < last_; ++step) {
        {
          std::unique_lock<std::mutex> lock(mutex_);
          cv_.wait(lock,
                   [&] { return stop_ || static_cast<int>(queue_.size()) < depth_; });
          if (stop_) return;
        }
        std::vector<TrainingSample> batch = Make(step);
        std::lock_guard<std::mutex> lock(mutex_);
        queue_.push_back(std::move(batch));
        cv_.notify_all();
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = std::current_exception();
      cv_.notify_all();
    }
  }

  const TrainingSampleSource& source_;
  const int batch_size_;
  int64_t next_;
  const int64_t last_;
  const int depth_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::vector<TrainingSample>> queue_;
  std::exception_ptr error_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace

void PoemTrainerOptions::Check(const std::string& source) const {
  RequireGreater(source, "steps", steps, 0);
  RequireGreater(source, "batch_size", batch_size, 0);
  RequireGreater(source, "learning_rate", learning_rate, 0);
  RequireAtLeast(source, "warmup_steps", warmup_steps, 0);
  RequireInRange(source, "decay_at", decay_at, 0, 1);
  RequireGreater(source, "decay_factor", decay_factor, 0);
  RequireAtLeast(source, "grad_clip_norm", grad_clip_norm, 0);
  RequireGreater(source, "checkpoint_every", checkpoint_every, 0);
  RequireGreater(source, "keep_checkpoints", keep_checkpoints, 0);
  RequireAtLeast(source, "keep_every", keep_every, 0);
  if (keep_every > 0 && keep_every % checkpoint_every != 0) {
    // Otherwise some or all of the steps it names never get a checkpoint.
    throw InputError(
        source, "keep_every",
        "a multiple of checkpoint_every (" + std::to_string(checkpoint_every) + ")",
        std::to_string(keep_every));
  }
  RequireGreater(source, "log_every", log_every, 0);
  RequireAtLeast(source, "validate_every", validate_every, 0);
  RequireAtLeast(source, "validation_samples", validation_samples, 0);
  RequireGreater(source, "threads", threads, 0);
  RequireAtLeast(source, "prefetch_batches", prefetch_batches, 0);
  RequireAtLeast(source, "init_step", init_step, 0);
  if (out_dir.empty()) throw InputError(source, "out_dir", "a folder", "empty");
  RequireAtLeast(source, "heatmap_weight", heatmap_weight, 0);
  RequireAtLeast(source, "triangulation_weight", triangulation_weight, 0);
  RequireAtLeast(source, "joints_weight", joints_weight, 0);
  RequireAtLeast(source, "vertices_weight", vertices_weight, 0);
  RequireAtLeast(source, "joints_2d_weight", joints_2d_weight, 0);
  RequireAtLeast(source, "mask_weight", mask_weight, 0);
}

double PoemLearningRate(const PoemTrainerOptions& o, int64_t step) {
  double lr = o.learning_rate;
  if (step < o.warmup_steps) lr *= 0.1 + 0.9 * static_cast<double>(step) / o.warmup_steps;
  if (step >= static_cast<int64_t>(o.decay_at * o.steps)) lr *= o.decay_factor;
  return lr;
}

PoemValidation ValidatePoem(PoemModel& model, const TrainingSampleSource& source,
                            int count, int batch_size) {
  PoemValidation v;
  double joints = 0, verts = 0;
  MaskIouCounts masks;
  bool any_mask = false;
  for (int first = 0; first < count; first += batch_size) {
    const std::vector<TrainingSample> samples =
        SampleRange(source, first, std::min(count, first + batch_size));
    const std::vector<PoemPrediction> pred = PredictPoem(model, samples);
    for (size_t i = 0; i < samples.size(); ++i) {
      joints += MeanPointError(pred[i].joints_3d, samples[i].joints_3d);
      verts += MeanPointError(pred[i].vertices_3d, samples[i].vertices_3d);
      any_mask |= masks.Add(pred[i], samples[i]);
    }
    v.samples += static_cast<int>(samples.size());
  }
  if (v.samples > 0) {
    v.mpjpe_mm = 1000.0 * joints / v.samples;
    v.mpvpe_mm = 1000.0 * verts / v.samples;
  }
  if (any_mask) v.mask_iou = masks.Iou();
  return v;
}

struct PoemTrainer::State {
  PoemConfig config;
  PoemTrainerOptions options;
  PoemTrainerHooks hooks;
  const TrainingSampleSource& train;
  const TrainingSampleSource* validation;
  PoemModel model{nullptr};
  PoemLossOptions loss;
  torch::Tensor regressor;
  std::unique_ptr<torch::optim::Adam> optimizer;

  State(const PoemConfig& c, const TrainingSampleSource& t, const TrainingSampleSource* v,
        const PoemTrainerOptions& o, PoemTrainerHooks h)
      : config(c), options(o), hooks(std::move(h)), train(t), validation(v) {
    loss.heatmap_weight = o.heatmap_weight;
    loss.triangulation_weight = o.triangulation_weight;
    loss.joints_weight = o.joints_weight;
    loss.vertices_weight = o.vertices_weight;
    loss.joints_2d_weight = o.joints_2d_weight;
    loss.mask_weight = o.mask_weight;
  }

  std::string Path(const std::string& name) const {
    return (fs::path(options.out_dir) / name).string();
  }

  void MakeOptimizer() {
    optimizer = std::make_unique<torch::optim::Adam>(
        options.mask_head_only ? model->mask_head->parameters() : model->parameters(),
        torch::optim::AdamOptions(options.learning_rate));
  }

  void SetLearningRate(double lr) {
    for (auto& group : optimizer->param_groups()) {
      static_cast<torch::optim::AdamOptions&>(group.options()).lr(lr);
    }
  }

  void SaveCheckpoint(int64_t step) {
    fs::create_directories(Path("checkpoints"));
    const std::string base = "checkpoints/" + StepName(step);
    SavePoemCheckpoint(model, Path(base + ".pt"));  // atomically
    torch::serialize::OutputArchive archive;
    optimizer->save(archive);
    archive.write("step", torch::tensor(static_cast<int64_t>(step)));
    SaveArchiveAtomically(archive, Path(base + ".optim"));
    nlohmann::json latest = ResumeSettings(options);
    latest["step"] = step;
    latest["model"] = base + ".pt";
    latest["optimizer"] = base + ".optim";
    latest["config"] = nlohmann::json::parse(config.ToJson());
    latest["steps"] = options.steps;
    WriteFileAtomically(Path("latest.json"), latest.dump(2) + "\n");
    // Drop old checkpoints beyond keep_checkpoints, but the weights at keep_every.
    std::vector<std::string> stems;
    for (const auto& e : fs::directory_iterator(Path("checkpoints"))) {
      const std::string name = e.path().filename().string();
      if (name.size() > 3 && name.substr(name.size() - 3) == ".pt" &&
          name.rfind("step_", 0) == 0) {
        stems.push_back(name.substr(0, name.size() - 3));
      }
    }
    std::sort(stems.begin(), stems.end());
    for (size_t i = 0; i + options.keep_checkpoints < stems.size(); ++i) {
      char* end = nullptr;
      const int64_t stem_step = std::strtoll(stems[i].c_str() + 5, &end, 10);
      const bool numbered = end != stems[i].c_str() + 5 && *end == '\0';
      if (options.keep_every == 0 || !numbered || stem_step % options.keep_every != 0) {
        fs::remove(Path("checkpoints/" + stems[i] + ".pt"));
      }
      fs::remove(Path("checkpoints/" + stems[i] + ".optim"));
    }
  }

  // The step training starts from: the run's latest checkpoint when resuming, else
  // init_weights at init_step, else 0. Drops log rows written after that step.
  int64_t StartStep(bool resume) {
    const bool has_run = fs::exists(Path("latest.json"));
    if (has_run && !resume) {
      throw InputError(options.out_dir, "run folder", "an empty folder (or --resume)",
                       "it already holds a run (latest.json)");
    }
    int64_t step = 0;
    if (has_run) {
      step = LoadLatest();
    } else if (!options.init_weights.empty()) {
      LoadPoemCheckpointInto(model, options.init_weights, /*as_init_weights=*/true);
      step = options.init_step;
    }
    TruncateCsv(Path("loss.csv"), step);
    TruncateCsv(Path("validation.csv"), step);
    return step;
  }

  // One optimiser step on `samples` with learning rate `lr`. Torch's random state is
  // reseeded from (seed, step) so a resumed run repeats the same dropout and noise.
  TrainStepResult TrainOneStep(const std::vector<TrainingSample>& samples, int64_t step,
                               double lr) {
    const PoemTrainingBatch tb = ToPoemTrainingBatch(samples);
    torch::manual_seed(
        SplitMix64(options.seed ^ SplitMix64(static_cast<uint64_t>(step))));
    SetLearningRate(lr);
    TrainStepOptions step_options;
    step_options.grad_clip_norm = options.grad_clip_norm;
    const TrainStepResult r =
        options.mask_head_only
            ? TrainMaskHeadStep(model, *optimizer, tb.batch, tb.targets, step_options)
            : TrainStep(model, *optimizer, tb.batch, tb.targets, regressor, loss,
                        step_options);
    if (!std::isfinite(r.total)) {
      throw Error("training diverged at step " + std::to_string(step) +
                  " (loss not finite); resume from the last checkpoint with a lower "
                  "learning_rate");
    }
    return r;
  }

  // Appends a row to loss.csv and reports a progress line (rate over the steps since
  // the last log, ETA to `end`); restarts the clock's window.
  void LogStep(int64_t step, int64_t end, double lr, const TrainStepResult& r,
               StepClock* clock) {
    const auto now = Clock::now();
    const double window =
        std::chrono::duration<double>(now - clock->window_start).count();
    const double per_step = window / std::max<int64_t>(1, clock->window_steps);
    const double rate = options.batch_size / std::max(per_step, 1e-9);
    const double wall = std::chrono::duration<double>(now - clock->start).count();
    std::ostringstream header, row, line;
    header << "step,lr,total";
    row << step << "," << lr << "," << r.total;
    line << "step " << step << "/" << options.steps;
    if (end < options.steps) line << " (stop at " << end << ")";
    line << " loss " << r.total;
    for (const auto& [name, value] : r.terms) {
      header << "," << name;
      row << "," << value;
    }
    for (const auto& [name, value] : r.terms) {
      if (name == "heatmap_joints" || name == "triangulated_joints" ||
          name == "joints_3d" || name == "vertices_3d" || name == "masks") {
        line << " " << name << " " << value;
      }
    }
    header << ",samples_per_s,wall_s";
    row << "," << rate << "," << wall;
    char rate_text[64];
    std::snprintf(rate_text, sizeof(rate_text), " | %.2f samples/s lr %.2g ETA ", rate,
                  lr);
    line << rate_text << Duration(per_step * (end - step));
    AppendLine(Path("loss.csv"), header.str(), row.str());
    if (hooks.progress) hooks.progress(line.str());
    clock->window_start = now;
    clock->window_steps = 0;
  }

  // Validates on the held-out samples, appends a row to validation.csv and reports it.
  PoemValidation ValidateAndLog(int64_t step) {
    PoemValidation v =
        ValidatePoem(model, *validation, options.validation_samples, options.batch_size);
    v.step = step;
    std::ostringstream row;
    std::string header = "step,mpjpe_mm,mpvpe_mm,samples";
    row << step << "," << v.mpjpe_mm << "," << v.mpvpe_mm << "," << v.samples;
    if (config.mask_head) {
      header += ",mask_iou";
      row << "," << v.mask_iou;
    }
    AppendLine(Path("validation.csv"), header, row.str());
    if (hooks.progress) {
      char text[160];
      std::snprintf(text, sizeof(text),
                    "validation at step %lld: MPJPE %.2f mm, MPVPE %.2f mm (%d samples)",
                    static_cast<long long>(step), v.mpjpe_mm, v.mpvpe_mm, v.samples);
      std::string line = text;
      if (v.mask_iou >= 0) {
        std::snprintf(text, sizeof(text), ", mask IoU %.3f", v.mask_iou);
        line += text;
      }
      hooks.progress(line);
    }
    return v;
  }

  int64_t LoadLatest() {
    const LatestCheckpoint latest = ReadLatestJson(Path("latest.json"));
    CheckResumeSettings(latest.settings, ResumeSettings(options), Path("latest.json"));
    LoadPoemCheckpointInto(model, Path(latest.model));
    const std::string optim = Path(latest.optimizer);
    torch::Tensor step;
    try {
      torch::serialize::InputArchive archive;
      archive.load_from(optim);
      optimizer->load(archive);
      archive.read("step", step);
    } catch (const c10::Error& e) {  // truncated, damaged or of another network
      throw InputError(optim, "",
                       "the optimizer state handlabel train wrote with the checkpoint "
                       "(to go on from the weights alone, start a new run with "
                       "--init-weights " + Path(latest.model) + ")",
                       "unreadable: " + TorchErrorText(e));
    }
    return step.item<int64_t>();
  }
};

PoemTrainer::PoemTrainer(const PoemConfig& config, const HandModel& hand_model,
                         const TrainingSampleSource& train,
                         const TrainingSampleSource* validation,
                         const PoemTrainerOptions& options, PoemTrainerHooks hooks)
    : state_(
          std::make_unique<State>(config, train, validation, options, std::move(hooks))) {
  options.Check("trainer options");
  config.Check("POEM config");
  if (hand_model.num_vertices() != PoemConfig::kNumVertices) {
    throw InputError(
        "trainer", "hand model",
        std::to_string(PoemConfig::kNumVertices) + " vertices (MANO topology)",
        std::to_string(hand_model.num_vertices()));
  }
  if (train.num_views() != config.num_views || train.crop_size() != config.crop_size) {
    throw InputError("trainer", "training samples",
                     std::to_string(config.num_views) + " views of " +
                         std::to_string(config.crop_size) + " px (the network config)",
                     std::to_string(train.num_views()) + " views of " +
                         std::to_string(train.crop_size()) + " px");
  }
  if (options.mask_head_only && !config.mask_head) {
    throw InputError("trainer", "mask_head_only", "a network with mask_head: true",
                     "a network without a mask head");
  }
  state_->regressor = PoemKeypointRegressor(hand_model);
  state_->model = MakeRandomPoemModel(config, options.seed);
  state_->MakeOptimizer();
}

PoemTrainer::~PoemTrainer() = default;

void PoemTrainer::SaveWeights(const std::string& path, bool half) {
  if (!half) {
    SavePoemCheckpoint(state_->model, path);
    return;
  }
  PoemModel copy = MakeRandomPoemModel(state_->config, 0);
  LoadPoemStateDict(copy, PoemStateDict(state_->model), "trained model");
  copy->to(torch::kHalf);
  SavePoemCheckpoint(copy, path);
}

PoemTrainSummary PoemTrainer::Run(bool resume, int64_t stop_at_step) {
  State& s = *state_;
  const PoemTrainerOptions& o = s.options;
  torch::set_num_threads(o.threads);
  fs::create_directories(o.out_dir);
  const FileLock writer =
      LockFolderForWriting(o.out_dir, "train", "train.out_dir (--out)", "");
  if (s.hooks.folder_locked) s.hooks.folder_locked();
  PoemTrainSummary summary;
  const bool new_run = !fs::exists(s.Path("latest.json"));
  int64_t step = s.StartStep(resume);
  summary.start_step = step;
  if (new_run && o.validate_at_start && s.validation && o.validation_samples > 0) {
    summary.last_validation = s.ValidateAndLog(step);
    if (s.hooks.logs_written) s.hooks.logs_written();
  }
  const int64_t end =
      stop_at_step >= 0 ? std::min<int64_t>(stop_at_step, o.steps) : o.steps;
  StepClock clock;
  double last_loss = 0;
  {
    BatchProducer producer(s.train, o.batch_size, step, end, o.prefetch_batches);
    while (step < end) {
      const std::vector<TrainingSample> samples = producer.Next();
      const double lr = PoemLearningRate(o, step);
      const TrainStepResult r = s.TrainOneStep(samples, step, lr);
      last_loss = r.total;
      ++step;
      ++clock.window_steps;
      bool wrote_logs = false;
      if (step % o.log_every == 0 || step == end) {
        s.LogStep(step, end, lr, r, &clock);
        wrote_logs = true;
      }
      if (s.validation && o.validate_every > 0 && o.validation_samples > 0 &&
          (step % o.validate_every == 0 || step == o.steps)) {
        summary.last_validation = s.ValidateAndLog(step);
        wrote_logs = true;
      }
      if (step % o.checkpoint_every == 0 || step == end) s.SaveCheckpoint(step);
      if (wrote_logs && s.hooks.logs_written) s.hooks.logs_written();
    }
  }
  summary.end_step = step;
  summary.last_loss = last_loss;
  summary.seconds = std::chrono::duration<double>(Clock::now() - clock.start).count();
  return summary;
}

int64_t LatestPoemCheckpointStep(const std::string& out_dir) {
  const fs::path p = fs::path(out_dir) / "latest.json";
  if (!fs::exists(p)) return -1;
  return ReadLatestJson(p.string()).step;
}

std::string LatestPoemCheckpointModel(const std::string& out_dir) {
  const fs::path p = fs::path(out_dir) / "latest.json";
  if (!fs::exists(p)) return "";
  return (fs::path(out_dir) / ReadLatestJson(p.string()).model).string();
}

PoemConfig PoemCheckpointConfig(const std::string& path) {
  return ReadPoemCheckpointConfig(path);
}

void WritePoemCheckpointForViews(const std::string& in_path, int num_views,
                                 const std::string& out_path) {
  PoemConfig config = ReadPoemCheckpointConfig(in_path);
  config.num_views = num_views;
  PoemModel model(config);
  LoadPoemCheckpointInto(model, in_path, /*as_init_weights=*/true);
  model->to(torch::kHalf);
  SavePoemCheckpoint(model, out_path);
}

void ConvertPoemCheckpointToHalf(const std::string& in_path,
                                 const std::string& out_path) {
  ExportPoemCheckpointAverageAsHalf({in_path}, out_path);  // the mean of one is itself
}

void ExportPoemCheckpointAverageAsHalf(const std::vector<std::string>& in_paths,
                                       const std::string& out_path,
                                       const TrainingSampleSource* bn_source,
                                       int bn_samples, int batch_size) {
  PoemModel model = AveragePoemCheckpoints(in_paths);
  if (bn_source != nullptr && bn_samples > 0) {
    RecomputePoemBatchNorm(model, *bn_source, bn_samples, batch_size);
  }
  model->to(torch::kHalf);
  SavePoemCheckpoint(model, out_path);
}

}  // namespace handlabel
