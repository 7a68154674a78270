// Where a label job's time went (FrameRecord::stages, LabelSummary::stage_seconds): the
// runner on the in-memory test stages, each made slower by a known sleep and reporting a
// known part of it under a name of its own, as the in-job detector and the Ceres fitter
// do. The reported parts must come out under their names, exactly; the rest of each
// step under the runner's stage; every frame's stages must add up to its seconds and
// the summary's totals to the frames'.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include "core/stopwatch.h"
#include "pipeline/detect_frame_source.h"
#include "pipeline/frame_log.h"
#include "pipeline/label_outputs.h"
#include "tests/pipeline/label_test_stages.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using testing::TestCapture;
using testing::TestFitter;
using testing::TestPredictor;

constexpr auto kReadSleep = std::chrono::milliseconds(60);
constexpr double kReportedPalm = 0.05;  // of the read's 60 ms, "detected" (seconds)
constexpr auto kNetworkSleep = std::chrono::milliseconds(20);  // per batch
constexpr auto kFitSleep = std::chrono::milliseconds(20);
constexpr double kReportedSolve = 0.015;  // of the fit's 20 ms

// Seconds per frame id, thread-safe: how long a test stage's call took, as it saw it.
class CallSeconds {
 public:
  void Put(const std::string& frame, double seconds) const {
    std::lock_guard<std::mutex> lock(mutex_);
    seconds_[frame] = seconds;
  }
  double At(const std::string& frame) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return seconds_.at(frame);
  }

 private:
  mutable std::mutex mutex_;
  mutable std::map<std::string, double> seconds_;
};

// A reader that detects as it loads (as DetectorFrameSource does): it sleeps, and says
// that kReportedPalm of that was the palm model.
class SlowCapture : public TestCapture {
 public:
  using TestCapture::TestCapture;
  FrameInput Load(const std::string& id) const override {
    const auto start = std::chrono::steady_clock::now();
    FrameInput frame = TestCapture::Load(id);
    std::this_thread::sleep_for(kReadSleep);
    frame.stage_seconds["detect.palm"] = kReportedPalm;
    load_seconds.Put(id, SecondsSince(start));
    return frame;
  }
  CallSeconds load_seconds;
};

class SlowFitter : public TestFitter {
 public:
  LabelFit Fit(const LabelFitRequest& request) const override {
    const auto start = std::chrono::steady_clock::now();
    LabelFit fit = TestFitter::Fit(request);
    std::this_thread::sleep_for(kFitSleep);
    fit.stage_seconds["solve"] = kReportedSolve;
    fit_seconds.Put(request.frame->id, SecondsSince(start));
    return fit;
  }
  CallSeconds fit_seconds;
};

struct SlowStages {
  SlowCapture capture{12};
  TestPredictor predictor;
  SlowFitter fitter;
  SlowStages() {
    predictor.predict = [this](const std::vector<const FrameInput*>& frames) {
      std::this_thread::sleep_for(kNetworkSleep);
      return predictor.Predict(frames);
    };
  }
  LabelStageSet Set() { return testing::TestStageSet(capture, &predictor, &fitter); }
};

// What the job left: its summary, its shard log and its summary.json.
struct TimedRun {
  LabelSummary summary;
  std::vector<FrameRecord> records;
  nlohmann::json summary_json;
  std::map<std::string, double> load_seconds, fit_seconds;  // as the stages saw them
};

// One job for all tests of the suite (it sleeps ~0.5 s), run in the first test's
// scratch folder and read before that test ends (its folder goes then).
class LabelStageTimes : public ::testing::Test {
 protected:
  void SetUp() override {
    if (run_) return;
    const std::string out = testing::ScratchDir() + "/out";
    SlowStages stages;
    JobConfig job = testing::MakeTestJob(out, RefineMode::kAlways);  // batches of 3
    auto run = std::make_unique<TimedRun>();
    run->summary = RunLabelJob(job, stages.Set(), {});
    run->records = FrameLog::Read(ShardLogPath(out, {0, 1}));
    std::ifstream in(SummaryJsonPath(out));
    run->summary_json = nlohmann::json::parse(in);
    for (const FrameRecord& r : run->records) {
      run->load_seconds[r.frame] = stages.capture.load_seconds.At(r.frame);
      run->fit_seconds[r.frame] = stages.fitter.fit_seconds.At(r.frame);
    }
    run_ = std::move(run);
  }
  static void TearDownTestSuite() { run_.reset(); }
  const LabelSummary& summary() const { return run_->summary; }
  const std::vector<FrameRecord>& records() const { return run_->records; }
  const nlohmann::json& summary_json() const { return run_->summary_json; }
  const TimedRun& run() const { return *run_; }

 private:
  static std::unique_ptr<TimedRun> run_;
};
std::unique_ptr<TimedRun> LabelStageTimes::run_;

TEST_F(LabelStageTimes, EveryFrameHasItsStagesAndTheyAddUpToItsSeconds) {
  ASSERT_EQ(records().size(), 12u);
  for (const FrameRecord& r : records()) {
    ASSERT_EQ(r.status, "ok") << r.reason;
    std::set<std::string> names;
    double sum = 0;
    for (const auto& [stage, seconds] : r.stages) {
      names.insert(stage);
      EXPECT_GE(seconds, 0.0) << stage;
      sum += seconds;
    }
    // Every stage that ran, and no other (no overlays, no detections, no truth
    // evaluation in this job).
    EXPECT_EQ(names, (std::set<std::string>{"read", "detect.palm", "network", "checks",
                                            "fit.solve", "fit.other", "evaluate",
                                            "write.labels", "write.checksum", "other"}))
        << r.frame;
    EXPECT_NEAR(sum, r.seconds, 1e-9 * r.seconds) << r.frame;
  }
}

TEST_F(LabelStageTimes, ReportedPartsKeepTheirNamesAndTheRestGoesToTheStep) {
  for (const FrameRecord& r : records()) {
    // Exactly what the reader and the fitter reported: neither lost nor counted twice.
    EXPECT_NEAR(r.stages.at("detect.palm"), kReportedPalm, 1e-12) << r.frame;
    EXPECT_NEAR(r.stages.at("fit.solve"), kReportedSolve, 1e-12) << r.frame;
    // The rest of each call lands in the step that made it: all of the call counted,
    // and the reported part not a second time (that would add all of it again; the
    // margin left is the runner's own work around the call).
    const double load = run().load_seconds.at(r.frame);
    const double read = r.stages.at("read") + r.stages.at("detect.palm");
    EXPECT_GE(read, load - 1e-9) << r.frame;
    EXPECT_LT(read, load + kReportedPalm) << r.frame;
    const double fit_call = run().fit_seconds.at(r.frame);
    const double fit = r.stages.at("fit.solve") + r.stages.at("fit.other");
    EXPECT_GE(fit, fit_call - 1e-9) << r.frame;
    EXPECT_LT(fit, fit_call + kReportedSolve) << r.frame;
    // Each frame's share of its batch of 3 in the network.
    EXPECT_GE(r.stages.at("network"),
              std::chrono::duration<double>(kNetworkSleep).count() / 3 - 1e-4)
        << r.frame;
  }
}

TEST_F(LabelStageTimes, SummaryTotalsAreTheFramesSumsAndFitInThreadsTimesWall) {
  std::map<std::string, double> sums;
  double frame_seconds = 0;
  for (const FrameRecord& r : records()) {
    for (const auto& [stage, seconds] : r.stages) sums[stage] += seconds;
    frame_seconds += r.seconds;
  }
  ASSERT_EQ(summary().stage_seconds.size(), sums.size());
  double total = 0;
  for (const auto& [stage, seconds] : sums) {
    EXPECT_NEAR(summary().stage_seconds.at(stage), seconds, 1e-9) << stage;
    total += summary().stage_seconds.at(stage);
  }
  EXPECT_EQ(summary().stage_frames, 12);
  EXPECT_NEAR(total, frame_seconds, 1e-9);
  EXPECT_NEAR(summary().frame_seconds, frame_seconds, 1e-9);
  // The frames' stages ran on the job's 2 threads: they cannot hold more time than
  // 2 x the wall time (time counted twice would).
  EXPECT_EQ(summary().threads, 2);
  EXPECT_LE(total, summary().threads * summary().wall_seconds + 1e-3);
  // The job's summary.json (written by the run's merge) carries the same.
  const nlohmann::json& j = summary_json();
  EXPECT_NEAR(j.at("stage_seconds").at("network").get<double>(), sums.at("network"),
              1e-9);
  EXPECT_EQ(j.at("stage_frames").get<int>(), 12);
  EXPECT_EQ(j.at("threads").get<int>(), 2);
  EXPECT_GT(j.at("wall_seconds").get<double>(), 0.0);
}

TEST_F(LabelStageTimes, TheTableListsGroupsLongestFirstWithTheirParts) {
  const std::string table = summary().StageTable();
  EXPECT_THAT(table, HasSubstr("where the time went (12 frames"));
  EXPECT_THAT(table, HasSubstr("2 thread(s) x "));
  // Groups by their summed seconds; each group's parts below it.
  std::vector<std::pair<double, std::string>> groups;
  std::map<std::string, double> group_seconds;
  for (const auto& [stage, seconds] : summary().stage_seconds)
    group_seconds[stage.substr(0, stage.find('.'))] += seconds;
  for (const auto& [group, seconds] : group_seconds) groups.emplace_back(-seconds, group);
  std::sort(groups.begin(), groups.end());
  size_t at = 0;
  for (const auto& [unused, group] : groups) {
    const size_t row = table.find("\n  " + group + " ");
    ASSERT_NE(row, std::string::npos) << group << "\n" << table;
    EXPECT_GT(row, at) << group << " out of order\n" << table;
    at = row;
  }
  EXPECT_LT(table.find("\n  fit "), table.find("\n    .solve "));
}

// A job that tracks the hand calls the detector itself on some frames only: there the
// detector's reported parts come out under their names and the rest of its call as
// detect.other; frames labelled from the previous label's crops have no detect stage.
TEST(LabelStageTimesTracked, TheJobsOwnDetectorCallsAreTimedWhereTheyRan) {
  const std::string out = testing::ScratchDir() + "/out";
  TestCapture capture{9};
  capture.without_2d = true;
  TestPredictor network;
  TestFitter fitter;
  constexpr double kReportedLandmarks = 0.004;
  std::set<std::string> detected;
  std::mutex mutex;
  LabelStageSet set = testing::TestStageSet(capture, &network, &fitter);
  set.find_keypoints_2d = [&](FrameInput* frame) {
    std::this_thread::sleep_for(std::chrono::milliseconds(6));
    for (const RigCamera& camera : frame->rig.cameras()) {
      frame->keypoints_2d.push_back(
          testing::ProjectKeypoints(camera, frame->ground_truth->keypoints));
    }
    frame->stage_seconds["detect.landmarks"] = kReportedLandmarks;
    std::lock_guard<std::mutex> lock(mutex);
    detected.insert(frame->id);
  };
  JobConfig job = testing::MakeTestJob(out, RefineMode::kFallback);
  job.keypoints = KeypointSource::kFiles;
  job.keypoints_from_detector = true;
  job.detector_every = 3;
  const LabelSummary summary = RunLabelJob(job, set, {});
  ASSERT_EQ(summary.ok, 9);
  ASSERT_EQ(detected.size(), 3u);  // frames 0, 3, 6
  for (const FrameRecord& r : FrameLog::Read(ShardLogPath(out, {0, 1}))) {
    if (detected.count(r.frame)) {
      EXPECT_NEAR(r.stages.at("detect.landmarks"), kReportedLandmarks, 1e-12) << r.frame;
      EXPECT_GE(r.stages.at("detect.other"), 0.006 - kReportedLandmarks - 1e-4)
          << r.frame;
    } else {
      EXPECT_EQ(r.stages.count("detect.landmarks") + r.stages.count("detect.other"), 0u)
          << r.frame;
    }
    EXPECT_GT(r.stages.at("network"), 0.0) << r.frame;
  }
  EXPECT_NEAR(summary.stage_seconds.at("detect.landmarks"), 3 * kReportedLandmarks,
              1e-12);
}

TEST(DetectorSeconds, ModelTimesSplitTheWallTimeAndParallelViewsAreScaledToIt) {
  FrameHandResult result;
  result.views.resize(2);
  result.views[0].palm_seconds = 0.3;
  result.views[0].landmarks_seconds = 0.1;
  result.views[1].landmarks_seconds = 0.1;
  StageSeconds serial;
  AddDetectorSeconds(result, 1.0, &serial);
  EXPECT_NEAR(serial.at("detect.palm"), 0.3, 1e-12);
  EXPECT_NEAR(serial.at("detect.landmarks"), 0.2, 1e-12);
  EXPECT_NEAR(serial.at("detect.other"), 0.5, 1e-12);
  // Views in parallel: 0.5 s of model calls in 0.25 s of wall time.
  StageSeconds parallel;
  AddDetectorSeconds(result, 0.25, &parallel);
  EXPECT_NEAR(TotalStageSeconds(parallel), 0.25, 1e-12);
  EXPECT_NEAR(parallel.at("detect.palm") / parallel.at("detect.landmarks"), 1.5, 1e-12);
  EXPECT_NEAR(parallel.at("detect.other"), 0.0, 1e-12);
}

}  // namespace
}  // namespace handlabel
