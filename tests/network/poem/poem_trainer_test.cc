#include "network/poem/poem_trainer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include "core/errors.h"
#include "geometry/rigid3.h"
#include "network/poem/poem_batch_norm_update.h"
#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_training_batch.h"
#include "tests/network/poem/poem_test_util.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// A HandModel with 778 vertices whose regressor averages a few vertices per joint.
HandModel MakeRegressorModel() {
  HandModel m;
  m.v_template = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>::Zero(778, 3);
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < kNumHandJoints; ++j)
    for (int k = 0; k < 4; ++k) t.emplace_back(j, (j * 37 + k * 11) % 778, 0.25);
  m.joint_regressor.resize(kNumHandJoints, 778);
  m.joint_regressor.setFromTriplets(t.begin(), t.end());
  return m;
}

// Samples of a 2-camera rig around a hand-sized blob 0.6 m in front of camera 0;
// sample i depends only on (seed, i), or on seed alone when `fixed`. With `masks`,
// every view also shows a bright disc and has its mask.
class FakeSamples : public TrainingSampleSource {
 public:
  FakeSamples(const PoemConfig& c, uint64_t seed, bool fixed, bool masks = false)
      : c_(c), seed_(seed), fixed_(fixed), masks_(masks) {}
  int num_views() const override { return c_.num_views; }
  int crop_size() const override { return c_.crop_size; }
  TrainingSample Sample(int64_t index) const override {
    std::mt19937_64 rng(seed_ * 1000003 + (fixed_ ? 0 : index));
    std::normal_distribution<double> normal(0, 1);
    const int S = c_.crop_size;
    TrainingSample s;
    s.index = index;
    const Eigen::Vector3d center(0.02 * normal(rng), 0.02 * normal(rng), 0.6);
    s.joints_3d.resize(21, 3);
    s.vertices_3d.resize(778, 3);
    for (int i = 0; i < 21; ++i)
      s.joints_3d.row(i) =
          center.transpose() +
          0.04 * Eigen::RowVector3d(normal(rng), normal(rng), normal(rng));
    for (int i = 0; i < 778; ++i)
      s.vertices_3d.row(i) =
          center.transpose() +
          0.04 * Eigen::RowVector3d(normal(rng), normal(rng), normal(rng));
    for (int n = 0; n < c_.num_views; ++n) {
      TrainingView v;
      Rigid3 cam_from_master;
      if (n > 0) {
        const double a = 2 * M_PI * n / (c_.num_views + 1);
        const Eigen::Vector3d eye = Eigen::Vector3d(0, 0, 0.6) +
                                    0.6 * Eigen::Vector3d(std::sin(a), 0.1, -std::cos(a));
        cam_from_master =
            LookAt(eye, Eigen::Vector3d(0, 0, 0.6), Eigen::Vector3d(0, -1, 0));
      }
      const Rigid3 master_from_cam = cam_from_master.Inverse();
      v.master_from_cam.setIdentity();
      v.master_from_cam.topRows<3>() = master_from_cam.ToMatrix();
      const double f = 2.0 * S;
      v.intrinsics << f, 0, S / 2.0, 0, f, S / 2.0, 0, 0, 1;
      for (int k = 0; k < 21; ++k) {
        const Eigen::Vector3d p = cam_from_master * Eigen::Vector3d(s.joints_3d.row(k));
        v.joints_2d.row(k) << f * p.x() / p.z() + S / 2.0, f * p.y() / p.z() + S / 2.0;
        v.joints_2d_weight[k] = 1;
      }
      v.image.resize(3 * S * S);
      std::uniform_real_distribution<float> u(-0.5f, 0.5f);
      for (float& x : v.image) x = u(rng);
      if (masks_) {
        std::uniform_real_distribution<double> where(0.3 * S, 0.7 * S);
        const double cx = where(rng), cy = where(rng), r = 0.2 * S;
        v.mask.assign(S * S, 0.0f);
        for (int y = 0; y < S; ++y) {
          for (int x = 0; x < S; ++x) {
            if (std::hypot(x - cx, y - cy) >= r) continue;
            v.mask[y * S + x] = 1.0f;
            for (int ch = 0; ch < 3; ++ch) v.image[(ch * S + y) * S + x] = 0.5f;
          }
        }
      }
      s.views.push_back(std::move(v));
    }
    return s;
  }

 private:
  PoemConfig c_;
  uint64_t seed_;
  bool fixed_;
  bool masks_;
};

PoemTrainerOptions TinyOptions(const std::string& dir) {
  PoemTrainerOptions o;
  o.steps = 6;
  o.batch_size = 2;
  o.learning_rate = 1e-3;
  o.warmup_steps = 2;
  o.checkpoint_every = 2;
  o.log_every = 1;
  o.validate_every = 3;
  o.validation_samples = 2;
  o.seed = 3;
  o.threads = 1;
  o.out_dir = dir;
  return o;
}

std::map<std::string, torch::Tensor> Weights(const std::string& run) {
  PoemModel m = LoadPoemCheckpoint(LatestPoemCheckpointModel(run));
  return PoemStateDict(m);
}

TEST(PoemTrainer, OverfitsAFixedBatch) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples fixed(c, 7, /*fixed=*/true);
  PoemTrainerOptions o = TinyOptions(testing::ScratchDir() + "/run");
  o.steps = 12;
  o.learning_rate = 2e-3;
  o.validate_every = 0;
  o.checkpoint_every = 12;
  std::vector<double> losses;
  PoemTrainerHooks hooks;
  hooks.progress = [&](const std::string& line) {
    losses.push_back(std::stod(line.substr(line.find("loss ") + 5)));
  };
  PoemTrainer trainer(c, MakeRegressorModel(), fixed, nullptr, o, hooks);
  const PoemTrainSummary s = trainer.Run(false);
  EXPECT_EQ(s.end_step, 12);
  ASSERT_EQ(losses.size(), 12u);
  EXPECT_LT(losses.back(), 0.7 * losses.front());
}

TEST(PoemTrainer, ResumeContinuesBitIdentically) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples train(c, 11, false), validation(c, 12, false);
  const HandModel hand = MakeRegressorModel();
  const std::string a = testing::ScratchDir() + "/a", b = testing::ScratchDir() + "/b";
  {
    PoemTrainer t(c, hand, train, &validation, TinyOptions(a));
    EXPECT_EQ(t.Run(false).end_step, 6);
  }
  {
    std::vector<std::string> lines;
    PoemTrainerHooks hooks;
    hooks.progress = [&](const std::string& line) { lines.push_back(line); };
    PoemTrainer t(c, hand, train, &validation, TinyOptions(b), hooks);
    EXPECT_EQ(t.Run(false, /*stop_at_step=*/3).end_step, 3);
    // The progress line names the stop, and its ETA counts down to it, not to step 6.
    ASSERT_FALSE(lines.empty());
    EXPECT_NE(lines.front().find("step 1/6 (stop at 3) loss "), std::string::npos)
        << lines.front();
  }
  EXPECT_EQ(LatestPoemCheckpointStep(b), 3);
  {
    // A fresh process would do the same: a new trainer, starting from random weights.
    PoemTrainer t(c, hand, train, &validation, TinyOptions(b));
    const PoemTrainSummary s = t.Run(/*resume=*/true);
    EXPECT_EQ(s.start_step, 3);
    EXPECT_EQ(s.end_step, 6);
  }
  const auto wa = Weights(a), wb = Weights(b);
  ASSERT_EQ(wa.size(), wb.size());
  for (const auto& [key, value] : wa) {
    EXPECT_TRUE(torch::equal(value, wb.at(key))) << key;
  }
  // The loss logs agree row for row (no duplicated rows after the resume).
  auto read = [](const std::string& p) {
    std::ifstream in(p);
    std::vector<std::string> cols;
    std::string line;
    while (std::getline(in, line)) {
      // Drop samples/s and wall time (the last two columns).
      for (int k = 0; k < 2; ++k) line = line.substr(0, line.rfind(','));
      cols.push_back(line);
    }
    return cols;
  };
  EXPECT_EQ(read(a + "/loss.csv"), read(b + "/loss.csv"));
  EXPECT_EQ(read(a + "/validation.csv"), read(b + "/validation.csv"));
}

TEST(PoemTrainer, RefusesToOverwriteARunWithoutResume) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples train(c, 1, false);
  PoemTrainerOptions o = TinyOptions(testing::ScratchDir() + "/run");
  o.steps = 1;
  PoemTrainer(c, MakeRegressorModel(), train, nullptr, o).Run(false);
  PoemTrainer again(c, MakeRegressorModel(), train, nullptr, o);
  EXPECT_THROW(again.Run(false), InputError);
}

// One writer per run folder: a second trainer on the folder while the first runs (two
// `train --resume` at once duplicated loss.csv rows) is refused naming the folder and
// the holder; the first completes with each step logged once; the lock is released at
// the end.
TEST(PoemTrainer, ASecondTrainerOnTheRunFolderIsRefusedAndTheFirstCompletes) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples train(c, 5, false);
  const HandModel hand = MakeRegressorModel();
  const std::string run = testing::ScratchDir() + "/run";
  PoemTrainerOptions o = TinyOptions(run);
  o.validate_every = 0;
  PoemTrainer second(c, hand, train, nullptr, o);
  std::string refusal;
  int folder_locked = 0;
  PoemTrainerHooks hooks;
  hooks.folder_locked = [&] {
    ++folder_locked;
    EXPECT_FALSE(std::filesystem::exists(run + "/loss.csv"));  // before any write
  };
  hooks.progress = [&](const std::string&) {
    if (refusal.empty()) refusal = testing::InputErrorOf([&] { second.Run(true); });
  };
  PoemTrainer first(c, hand, train, nullptr, o, hooks);
  EXPECT_EQ(first.Run(false).end_step, 6);
  EXPECT_EQ(folder_locked, 1);
  EXPECT_NE(refusal.find(run), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("in use by train, pid " + std::to_string(::getpid())),
            std::string::npos)
      << refusal;
  std::ifstream in(run + "/loss.csv");
  std::vector<std::string> steps;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) steps.push_back(line.substr(0, line.find(',')));
  EXPECT_EQ(steps, (std::vector<std::string>{"1", "2", "3", "4", "5", "6"}));
  EXPECT_EQ(second.Run(true).end_step, 6);  // released: the resume has nothing to do
}

// latest.json records what decides the samples (the caller's data settings), the batch
// size and the seed: a resume with another value of any of them is refused naming it
// (it continued silently on other data); the same settings resume. A truncated
// optimizer state names its file (it was a bare LibTorch message and backtrace).
TEST(PoemTrainer, ResumeWithOtherDataOrBatchesIsRefusedAndADamagedStateNamed) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples train(c, 5, false);
  const HandModel hand = MakeRegressorModel();
  const std::string run = testing::ScratchDir() + "/run";
  PoemTrainerOptions o = TinyOptions(run);
  o.steps = 2;
  o.validate_every = 0;
  o.data_settings = {{"synth", {{"seed", 4}, {"rig", {{"width", 320}}}}}};
  PoemTrainer(c, hand, train, nullptr, o).Run(false);
  const auto refusal = [&](const PoemTrainerOptions& other) {
    return testing::InputErrorOf(
        [&] { PoemTrainer(c, hand, train, nullptr, other).Run(true); });
  };
  o.steps = 4;
  PoemTrainerOptions other = o;
  other.data_settings["synth"]["seed"] = 5;
  std::string error = refusal(other);
  EXPECT_NE(error.find(run + "/latest.json"), std::string::npos) << error;
  EXPECT_NE(error.find("data.synth.seed"), std::string::npos) << error;
  EXPECT_NE(error.find("began with, 4"), std::string::npos) << error;
  EXPECT_NE(error.find("got 5"), std::string::npos) << error;
  other = o;
  other.data_settings["synth"]["rig"]["width"] = 640;
  EXPECT_NE(refusal(other).find("data.synth.rig.width"), std::string::npos);
  other = o;
  other.batch_size = 3;
  EXPECT_NE(refusal(other).find("field 'batch_size'"), std::string::npos);
  EXPECT_EQ(LatestPoemCheckpointStep(run), 2);  // nothing was trained by the refused
  PoemTrainer(c, hand, train, nullptr, o).Run(true);
  EXPECT_EQ(LatestPoemCheckpointStep(run), 4);

  const std::string optim = run + "/checkpoints/step_00000004.optim";
  ASSERT_TRUE(std::filesystem::exists(optim));
  std::filesystem::resize_file(optim, std::filesystem::file_size(optim) / 2);
  o.steps = 6;
  error = refusal(o);
  EXPECT_NE(error.find(optim), std::string::npos) << error;
  EXPECT_NE(error.find("unreadable"), std::string::npos) << error;
  EXPECT_EQ(error.find("Exception raised from"), std::string::npos) << error;
}

TEST(PoemTrainer, LearningRateScheduleWarmsUpAndDecays) {
  PoemTrainerOptions o;
  o.steps = 1000;
  o.learning_rate = 1e-3;
  o.warmup_steps = 100;
  o.decay_at = 0.7;
  o.decay_factor = 0.1;
  EXPECT_DOUBLE_EQ(PoemLearningRate(o, 0), 1e-4);
  EXPECT_DOUBLE_EQ(PoemLearningRate(o, 50), 1e-3 * (0.1 + 0.9 * 0.5));
  EXPECT_DOUBLE_EQ(PoemLearningRate(o, 100), 1e-3);
  EXPECT_DOUBLE_EQ(PoemLearningRate(o, 699), 1e-3);
  EXPECT_DOUBLE_EQ(PoemLearningRate(o, 700), 1e-4);
}

TEST(PoemTrainer, MaskHeadAloneOntoTrainedWeights) {
  PoemConfig plain = TinyPoemConfig(2);
  const std::string dir = testing::ScratchDir();
  {  // "trained" weights without a head
    const FakeSamples train(plain, 5, false);
    PoemTrainerOptions o = TinyOptions(dir + "/base");
    o.steps = 2;
    PoemTrainer(plain, MakeRegressorModel(), train, nullptr, o).Run(false);
  }
  PoemConfig c = plain;
  c.mask_head = true;
  const FakeSamples train(c, 8, false, /*masks=*/true);
  const FakeSamples validation(c, 9, false, /*masks=*/true);
  PoemTrainerOptions o = TinyOptions(dir + "/masks");
  o.steps = 30;
  o.learning_rate = 1e-2;
  o.validate_every = 30;
  o.validation_samples = 4;
  o.checkpoint_every = 30;
  o.init_weights = LatestPoemCheckpointModel(dir + "/base");
  o.mask_head_only = true;
  std::vector<double> losses;
  PoemTrainerHooks hooks;
  hooks.progress = [&](const std::string& line) {
    if (line.rfind("step ", 0) == 0)
      losses.push_back(std::stod(line.substr(line.find("loss ") + 5)));
  };
  PoemTrainer trainer(c, MakeRegressorModel(), train, &validation, o, hooks);
  const PoemTrainSummary s = trainer.Run(false);
  ASSERT_EQ(losses.size(), 30u);
  EXPECT_LT(losses.back(), 0.7 * losses.front());
  // The validation IoU, recomputed with plain loops from the saved weights: cells
  // predicted (p > 0.5) against cells more than half covered, pooled over the samples.
  PoemModel trained = LoadPoemCheckpoint(LatestPoemCheckpointModel(dir + "/masks"));
  const int S = c.crop_size, M = c.mask_size();
  double intersection = 0, union_cells = 0;
  for (int i = 0; i < o.validation_samples; ++i) {
    const TrainingSample sample = validation.Sample(i);
    const PoemPrediction p = PredictPoem(trained, {sample}).at(0);
    for (size_t n = 0; n < sample.views.size(); ++n) {
      for (int ci = 0; ci < M; ++ci) {
        for (int cj = 0; cj < M; ++cj) {
          const double cover = testing::BlockMean(sample.views[n].mask, S, ci, cj);
          const bool truth = cover > 0.5, predicted = p.masks[n][ci * M + cj] > 0.5f;
          intersection += truth && predicted;
          union_cells += truth || predicted;
        }
      }
    }
  }
  ASSERT_GT(union_cells, 0);
  EXPECT_NEAR(s.last_validation.mask_iou, intersection / union_cells, 1e-9);
  // Everything but the head is the base run's, bit for bit.
  const auto base = Weights(dir + "/base");
  int head_keys = 0;
  for (const auto& [key, value] : Weights(dir + "/masks")) {
    if (key.rfind("mask_head.", 0) == 0) {
      ++head_keys;
      continue;
    }
    EXPECT_TRUE(torch::equal(base.at(key), value)) << key;
  }
  EXPECT_GT(head_keys, 0);
  std::ifstream csv(dir + "/masks/validation.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "step,mpjpe_mm,mpvpe_mm,samples,mask_iou");
  // A network without a head cannot train one.
  EXPECT_THROW(PoemTrainer(plain, MakeRegressorModel(), train, nullptr, o), InputError);
}

TEST(PoemTrainer, HalfCheckpointLoadsCloseToTheOriginal) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples train(c, 5, false);
  const std::string dir = testing::ScratchDir();
  PoemTrainerOptions o = TinyOptions(dir + "/run");
  o.steps = 1;
  PoemTrainer t(c, MakeRegressorModel(), train, nullptr, o);
  t.Run(false);
  ConvertPoemCheckpointToHalf(LatestPoemCheckpointModel(dir + "/run"), dir + "/half.pt");
  PoemModel full = LoadPoemCheckpoint(LatestPoemCheckpointModel(dir + "/run"));
  PoemModel half = LoadPoemCheckpoint(dir + "/half.pt");
  const auto fw = PoemStateDict(full), hw = PoemStateDict(half);
  for (const auto& [key, value] : fw) {
    if (!value.is_floating_point()) continue;
    EXPECT_TRUE(torch::allclose(value, hw.at(key), 2e-3, 1e-4)) << key;
  }
  EXPECT_LT(std::filesystem::file_size(dir + "/half.pt"),
            0.7 * std::filesystem::file_size(LatestPoemCheckpointModel(dir + "/run")));
}

TEST(PoemTrainer, KeepsEveryNthCheckpointsWeightsAndAveragesThem) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples train(c, 21, false);
  const std::string dir = testing::ScratchDir();
  PoemTrainerOptions o = TinyOptions(dir + "/run");
  o.checkpoint_every = 1;
  o.keep_checkpoints = 1;
  o.keep_every = 2;
  PoemTrainer(c, MakeRegressorModel(), train, nullptr, o).Run(false);
  std::set<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir + "/run/checkpoints")) {
    files.insert(e.path().filename().string());
  }
  // Steps 2 and 4 keep their weights only; step 6 is the latest (with its optimizer);
  // the odd steps are gone.
  const std::set<std::string> expected = {"step_00000002.pt", "step_00000004.pt",
                                          "step_00000006.pt", "step_00000006.optim"};
  EXPECT_EQ(files, expected);
  // A keep_every that is no multiple of checkpoint_every would keep nothing it names.
  PoemTrainerOptions odd = o;
  odd.checkpoint_every = 2;
  odd.keep_every = 3;
  EXPECT_THROW(odd.Check("test"), InputError);
  odd.keep_every = 4;
  EXPECT_NO_THROW(odd.Check("test"));

  const std::vector<std::string> paths = {dir + "/run/checkpoints/step_00000002.pt",
                                          dir + "/run/checkpoints/step_00000004.pt",
                                          dir + "/run/checkpoints/step_00000006.pt"};
  PoemModel mean = AveragePoemCheckpoints(paths);
  std::vector<std::map<std::string, torch::Tensor>> each;
  std::vector<PoemModel> models;
  for (const auto& p : paths) {
    models.push_back(LoadPoemCheckpoint(p));
    each.push_back(PoemStateDict(models.back()));
  }
  int differing = 0;
  for (const auto& [key, value] : PoemStateDict(mean)) {
    if (!value.is_floating_point()) {
      EXPECT_TRUE(torch::equal(value, each[2].at(key))) << key;  // the last file's
      continue;
    }
    // Element by element, with the sum taken in another order.
    const auto a = each[0].at(key).flatten(), b = each[1].at(key).flatten(),
               d = each[2].at(key).flatten(), m = value.flatten();
    for (int64_t k = 0; k < m.numel(); k += std::max<int64_t>(1, m.numel() / 7)) {
      const double want =
          (d[k].item<double>() + b[k].item<double>() + a[k].item<double>()) / 3;
      EXPECT_NEAR(m[k].item<double>(), want, 1e-6 * (1 + std::abs(want)))
          << key << " " << k;
    }
    differing += !torch::equal(each[0].at(key), each[2].at(key));
  }
  EXPECT_GT(differing, 10);  // training moved the weights: the mean is not trivial

  // One file averages to itself; files of another config are refused.
  PoemModel one = AveragePoemCheckpoints({paths[1]});
  for (const auto& [key, value] : PoemStateDict(one)) {
    EXPECT_TRUE(torch::equal(value, each[1].at(key))) << key;
  }
  PoemConfig other = TinyPoemConfig(2);
  other.num_decoder_blocks += 1;
  PoemModel different(other);
  SavePoemCheckpoint(different, dir + "/other.pt");
  EXPECT_THROW(AveragePoemCheckpoints({paths[0], dir + "/other.pt"}), InputError);
  EXPECT_THROW(AveragePoemCheckpoints({}), InputError);
}

// After the update, eval mode (running statistics) answers like training mode (the
// batch's own statistics) on the batch the statistics were measured on; before it, the
// initial statistics give other answers. Parameters do not move.
// A view of weight 0 (its hand not located, as inference's whole-image views) leaves the
// triangulation and the 2D loss: the triangulated joints do not move whatever its
// pixels show, while they do for a view of weight 1. All weights 1 keep the reference's
// unweighted batch.
TEST(PoemTrainingBatch, ViewWeightsReachTheTriangulationAndThe2dLoss) {
  const PoemConfig c = TinyPoemConfig(3);
  const FakeSamples source(c, 5, false);
  std::vector<TrainingSample> samples = {source.Sample(0), source.Sample(1)};
  EXPECT_FALSE(ToPoemTrainingBatch(samples).batch.view_weights.defined());
  PoemModel model = MakeRandomPoemModel(c, 2);
  model->eval();
  auto triangulated = [&](const std::vector<TrainingSample>& batch) {
    torch::NoGradGuard no_grad;
    return model->forward(ToPoemTrainingBatch(batch).batch).triangulated_joints.clone();
  };
  std::vector<TrainingSample> repainted = samples;
  for (float& x : repainted[1].views[2].image) x = -x;
  const double moved_weighted =
      (triangulated(samples) - triangulated(repainted)).abs().max().item<double>();
  EXPECT_GT(moved_weighted, 1e-4);

  samples[1].views[2].view_weight = 0;
  repainted[1].views[2].view_weight = 0;
  const PoemTrainingBatch batch = ToPoemTrainingBatch(samples);
  ASSERT_TRUE(batch.batch.view_weights.defined());
  EXPECT_EQ(batch.batch.view_weights[1][2].item<float>(), 0.0f);
  EXPECT_EQ(batch.batch.view_weights[1][1].item<float>(), 1.0f);
  EXPECT_EQ(batch.targets.joints_2d_weights[1][2].abs().sum().item<float>(), 0.0f);
  EXPECT_EQ(batch.targets.joints_2d_weights[0][2].sum().item<float>(), 21.0f);
  const double moved_unweighted =
      (triangulated(samples) - triangulated(repainted)).abs().max().item<double>();
  EXPECT_LT(moved_unweighted, 1e-6 * moved_weighted + 1e-9);
}

TEST(PoemBatchNormUpdate, EvalModeMatchesTrainingModeOnTheMeasuredBatch) {
  const PoemConfig c = TinyPoemConfig(2);
  const FakeSamples source(c, 31, false);
  PoemModel model = MakeRandomPoemModel(c, 4);
  const PoemBatch batch =
      ToPoemTrainingBatch({source.Sample(0), source.Sample(1), source.Sample(2)}).batch;
  auto heatmaps = [&](bool training) {
    torch::NoGradGuard no_grad;
    model->train(training);
    torch::manual_seed(3);
    return model->forward(batch).heatmaps.clone();
  };
  const torch::Tensor with_batch_statistics = heatmaps(true);
  std::map<std::string, torch::Tensor> before;
  for (const auto& [key, value] : PoemStateDict(model)) before[key] = value.clone();

  const double gap_before =
      (heatmaps(false) - with_batch_statistics).abs().max().item<double>();
  EXPECT_GT(RecomputePoemBatchNorm(model, source, /*samples=*/3, /*batch_size=*/3), 0);
  EXPECT_FALSE(model->is_training());
  const double gap_after =
      (heatmaps(false) - with_batch_statistics).abs().max().item<double>();
  EXPECT_GT(gap_before, 1e-3);
  // Not zero: running variances are unbiased, training mode divides by the biased one.
  EXPECT_LT(gap_after, 0.1 * gap_before) << gap_before;

  int running_changed = 0;
  for (const auto& [key, value] : PoemStateDict(model)) {
    const bool running = key.find("running_") != std::string::npos ||
                         key.find("num_batches_tracked") != std::string::npos;
    if (!running) {
      EXPECT_TRUE(torch::equal(value, before.at(key))) << key;
    } else {
      running_changed += !torch::equal(value, before.at(key));
    }
  }
  EXPECT_GT(running_changed, 0);
  for (const auto& m : model->modules(false)) {
    if (auto* bn = m->as<torch::nn::BatchNorm2d>()) {
      ASSERT_TRUE(bn->options.momentum().has_value());  // restored for later training
      EXPECT_DOUBLE_EQ(*bn->options.momentum(), 0.1);
    }
  }
}

}  // namespace
}  // namespace handlabel
