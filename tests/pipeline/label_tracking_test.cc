// A job that tracks the hand (evidence.detector_every): which frames are detected, what
// the network's crops are cut around, and that resumed and sharded runs label exactly
// as one uninterrupted run (pipeline/label_job.h).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <mutex>

#include "pipeline/frame_log.h"
#include "pipeline/label_job.h"
#include "pipeline/label_outputs.h"
#include "tests/pipeline/label_test_stages.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::TestCapture;
using testing::TestFitter;
using testing::TestPredictor;

JobConfig TrackedJob(const std::string& out, int every) {
  JobConfig job = testing::MakeTestJob(out, RefineMode::kFallback);
  job.keypoints = KeypointSource::kFiles;
  job.keypoints_from_detector = true;
  job.detector_every = every;
  return job;
}

// The test stages with a detector on demand (the frames' exact projections) and a
// record of what the network was shown.
struct TrackingStages {
  TestCapture capture{12};
  TestPredictor predictor;
  TestFitter fitter;
  mutable std::mutex mutex;
  std::vector<std::string> detected;            // in call order
  std::map<std::string, Points3d> crop_priors;  // the last prior a frame was cut with
  NetworkStage network;

  TrackingStages() {
    capture.without_2d = true;
    network = predictor;
    network.lanes = 2;
    network.predict = [this](const std::vector<const FrameInput*>& frames) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        for (const FrameInput* f : frames) crop_priors[f->id] = f->crop_prior;
      }
      std::vector<MeshPrediction> answers = predictor.Predict(frames);
      // Like a network, drawn a little towards where it was told the hand is (1 % of
      // the way: well within the checks), so labels show which prior made them.
      for (size_t i = 0; i < frames.size(); ++i) {
        const Points3d& prior = frames[i]->crop_prior;
        if (prior.rows() == 0) continue;
        const Eigen::RowVector3d pull =
            0.01 * (prior.colwise().mean() - answers[i].keypoints.colwise().mean());
        answers[i].keypoints.rowwise() += pull;
        answers[i].vertices.rowwise() += pull;
      }
      return answers;
    };
  }

  LabelStageSet Set() {
    LabelStageSet set = testing::TestStageSet(capture, &network, &fitter);
    set.find_keypoints_2d = [this](FrameInput* frame) {
      std::lock_guard<std::mutex> lock(mutex);
      detected.push_back(frame->id);
      for (const RigCamera& camera : frame->rig.cameras()) {
        frame->keypoints_2d.push_back(
            testing::ProjectKeypoints(camera, frame->ground_truth->keypoints));
      }
    };
    return set;
  }
};

Points3d LabelKeypoints(const std::string& out, const std::string& frame) {
  return ReadLabelFile(LabelFilePath(out, frame)).mesh.keypoints;
}

std::map<std::string, std::string> LabelBytes(const std::string& out,
                                              const std::vector<std::string>& frames) {
  std::map<std::string, std::string> bytes;
  for (const std::string& f : frames)
    bytes[f] = testing::ReadFileBytes(LabelFilePath(out, f));
  return bytes;
}

TEST(LabelTracking, DetectsEveryNthFrameAndWhereTheTrackedAnswerFails) {
  TrackingStages s;
  s.predictor.shifted = {"000005"};  // its answers fail the checks, tracked or not
  const std::string out = testing::ScratchDir() + "/out";
  const LabelSummary summary = RunLabelJob(TrackedJob(out, 4), s.Set(), {});
  EXPECT_EQ(summary.ok, 12);
  std::set<std::string> detected(s.detected.begin(), s.detected.end());
  EXPECT_EQ(detected, (std::set<std::string>{"000000", "000004", "000005", "000008"}));
  EXPECT_EQ(s.detected.size(), detected.size());  // each at most once
  EXPECT_EQ(summary.by_crops.at("detector"), 4);
  EXPECT_EQ(summary.by_crops.at("previous_label"), 8);
  EXPECT_EQ(summary.by_path.at("fallback_fit"), 1);  // 000005, from its detection
  for (const FrameRecord& r : FrameLog::Read(ShardLogPath(out, {0, 1}))) {
    EXPECT_EQ(r.crops, detected.count(r.frame) ? "detector" : "previous_label")
        << r.frame;
  }
}

TEST(LabelTracking, CropsAroundThePreviousLabelMovedOnByItsLastStep) {
  TrackingStages s;
  const std::string out = testing::ScratchDir() + "/out";
  RunLabelJob(TrackedJob(out, 4), s.Set(), {});
  const std::vector<std::string> ids = s.capture.FrameIds();
  for (size_t i = 0; i < ids.size(); ++i) {
    const Points3d& prior = s.crop_priors.at(ids[i]);
    if (i % 4 == 0) {  // anchors are cut around their detections
      EXPECT_EQ(prior.rows(), 0) << ids[i];
      continue;
    }
    const Points3d last = LabelKeypoints(out, ids[i - 1]);
    // After an anchor there is one label to go by; later, the step between two.
    const Points3d expected =
        (i - 1) % 4 == 0 ? last : Points3d(2 * last - LabelKeypoints(out, ids[i - 2]));
    ASSERT_EQ(prior.rows(), kNumHandKeypoints) << ids[i];
    EXPECT_LT((prior - expected).cwiseAbs().maxCoeff(), 1e-12) << ids[i];
  }
}

TEST(LabelTracking, ResumedAndShardedRunsLabelAsOneRun) {
  TrackingStages whole;
  const std::string out = testing::ScratchDir() + "/whole";
  RunLabelJob(TrackedJob(out, 5), whole.Set(), {});
  const std::vector<std::string> ids = whole.capture.FrameIds();
  const auto expected = LabelBytes(out, ids);

  // Interrupted after 7 frames: the log lost the later records, their labels are gone.
  TrackingStages again;
  const std::string resumed = testing::ScratchDir() + "/resumed";
  RunLabelJob(TrackedJob(resumed, 5), again.Set(), {});
  const std::string log_path = ShardLogPath(resumed, {0, 1});
  std::vector<FrameRecord> records = FrameLog::Read(log_path);
  fs::remove(log_path);
  {
    FrameLog log(log_path);
    for (const FrameRecord& r : records) {
      if (r.frame < ids[7]) {
        log.Record(r);
      } else {
        fs::remove(LabelFilePath(resumed, r.frame));
      }
    }
  }
  again.detected.clear();
  LabelRunOptions resume;
  resume.resume = true;
  RunLabelJob(TrackedJob(resumed, 5), again.Set(), resume);
  // Frame 7 crops around the labels of 6 and 5 read from their files; 10 is an anchor.
  EXPECT_EQ(again.detected, (std::vector<std::string>{ids[10]}));
  EXPECT_EQ(LabelBytes(resumed, ids), expected);

  TrackingStages sharded;
  const std::string shards = testing::ScratchDir() + "/shards";
  LabelRunOptions first, second;
  first.shard = {0, 2};
  second.shard = {1, 2};
  RunLabelJob(TrackedJob(shards, 5), sharded.Set(), second);
  RunLabelJob(TrackedJob(shards, 5), sharded.Set(), first);
  // Shard 1/2 starts at frame 6 and detects it; the job's anchors are 0, 5 and 10.
  std::set<std::string> detected(sharded.detected.begin(), sharded.detected.end());
  EXPECT_EQ(detected, (std::set<std::string>{ids[0], ids[5], ids[6], ids[10]}));
  const auto shard_labels = LabelBytes(shards, ids);
  for (const std::string& f : ids) {
    if (f == ids[6] || f == ids[7] || f == ids[8] || f == ids[9]) continue;
    EXPECT_EQ(shard_labels.at(f), expected.at(f)) << f;
  }
}

}  // namespace
}  // namespace handlabel
