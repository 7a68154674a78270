#include "pipeline/label_job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "core/errors.h"
#include "formats/sha256.h"
#include "pipeline/frame_log.h"
#include "pipeline/label_outputs.h"
#include "tests/pipeline/label_test_stages.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::TestCapture;
using testing::TestFitter;
using testing::TestPredictor;

JobConfig MakeJob(const std::string& out, RefineMode mode) {
  return testing::MakeTestJob(out, mode);
}

struct Stages {
  TestCapture capture{12};
  TestPredictor predictor;
  TestFitter fitter;
  LabelStageSet Set(bool with_network = true) {
    return testing::TestStageSet(capture, with_network ? &predictor : nullptr, &fitter);
  }
};

std::map<std::string, std::string> LabelPaths(const std::string& out) {
  std::map<std::string, std::string> paths;
  for (const FrameRecord& r : FrameLog::Read(ShardLogPath(out, {0, 1}))) {
    if (r.status == "ok") paths[r.frame] = r.path;
  }
  return paths;
}

TEST(LabelJob, FallbackModeKeepsGoodNetworkAnswersAndFitsTheOthers) {
  Stages s;
  s.predictor.shifted = {"000002", "000007"};
  const std::string out = testing::ScratchDir() + "/out";
  const LabelSummary summary =
      RunLabelJob(MakeJob(out, RefineMode::kFallback), s.Set(), {});
  EXPECT_EQ(summary.ok, 12);
  EXPECT_EQ(summary.failed, 0);
  EXPECT_EQ(summary.by_path.at("network"), 10);
  EXPECT_EQ(summary.by_path.at("fallback_fit"), 2);
  const LabelRecord bad = ReadLabelFile(LabelFilePath(out, "000002"));
  EXPECT_EQ(bad.path, LabelPath::kFallbackFit);
  EXPECT_FALSE(bad.quality.Passed());
  EXPECT_THAT(bad.fit.at("why").get<std::string>(), HasSubstr("view_agreement"));
  const LabelRecord good = ReadLabelFile(LabelFilePath(out, "000003"));
  EXPECT_EQ(good.path, LabelPath::kNetwork);
  EXPECT_TRUE(good.quality.Passed());
  EXPECT_EQ(good.provenance.network_model, "test-predictor");
  EXPECT_EQ(good.provenance.job_hash,
            JobHash(MakeJob(out, RefineMode::kFallback), s.predictor.weights_sha256));
  EXPECT_TRUE(fs::exists(MeshFilePath(out, "000003", "ply")));
  // The network's answer is the ground truth on good frames: zero error, full AUC.
  EXPECT_NEAR(summary.metrics.at("network").at("mpjpe_mm").Mean(), 0.0, 1e-9);
  EXPECT_NEAR(summary.metrics.at("network").at("auc").Mean(), 1.0, 1e-12);
  EXPECT_EQ(summary.metrics.at("network_raw").at("mpjpe_mm").count, 12);
  // A one-shard run merges itself.
  EXPECT_TRUE(fs::exists(ManifestPath(out)));
}

// The network stage's lanes: at most `lanes` batches in the network at once, every
// batch predicted exactly once, and the same labels whatever the lane count.
TEST(LabelJob, NetworkLanesBoundTheBatchesInTheNetworkAndKeepTheLabels) {
  std::map<int, std::map<std::string, std::string>> labels;
  for (const int lanes : {1, 2, 3}) {
    Stages s;
    s.predictor.lanes = lanes;
    s.predictor.hold = std::chrono::milliseconds(1000);
    const std::string out = testing::ScratchDir() + "/lanes" + std::to_string(lanes);
    JobConfig job = MakeJob(out, RefineMode::kFallback);
    job.threads = 4;
    job.batch_size = 1;
    const LabelSummary summary = RunLabelJob(job, s.Set(), {});
    EXPECT_EQ(summary.ok, 12);
    EXPECT_EQ(s.predictor.batches.load(), 12) << lanes << " lanes";
    EXPECT_EQ(s.predictor.predicted.load(), 12) << lanes << " lanes";
    EXPECT_LE(s.predictor.most_inside.load(), lanes);
    // Each batch waits up to 1 s for another: lanes that may overlap do.
    if (lanes > 1) {
      EXPECT_GE(s.predictor.most_inside.load(), 2);
    }
    for (const auto& [frame, path] : LabelPaths(out)) {
      labels[lanes][frame] = testing::ReadFileBytes(LabelFilePath(out, frame));
    }
  }
  EXPECT_EQ(labels[1].size(), 12u);
  EXPECT_EQ(labels[2], labels[1]);
  EXPECT_EQ(labels[3], labels[1]);
}

TEST(LabelJob, RefineAlwaysRefinesEveryNetworkAnswer) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  const LabelSummary summary =
      RunLabelJob(MakeJob(out, RefineMode::kAlways), s.Set(), {});
  EXPECT_EQ(summary.by_path.at("refined"), 12);
  EXPECT_EQ(s.fitter.fits.load(), 12);
  const LabelRecord label = ReadLabelFile(LabelFilePath(out, "000000"));
  EXPECT_TRUE(label.fit.at("refined_from_network").get<bool>());
}

TEST(LabelJob, RefineAlwaysWithoutNetworkFitsFromFileEvidence) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  JobConfig job = MakeJob(out, RefineMode::kAlways);
  job.network_weights = "";
  job.keypoints = KeypointSource::kFiles;
  const LabelSummary summary = RunLabelJob(job, s.Set(false), {});
  EXPECT_EQ(summary.by_path.at("fallback_fit"), 12);
  EXPECT_LT(summary.metrics.at("labels").at("mpjpe_mm").Mean(), 1e-6);
  const LabelRecord label = ReadLabelFile(LabelFilePath(out, "000004"));
  EXPECT_EQ(label.provenance.network_model, "");
  EXPECT_TRUE(label.quality.flags.empty());
}

TEST(LabelJob, RefineOffWritesTheNetworkAnswerWithItsFlags) {
  Stages s;
  s.predictor.shifted = {"000001"};
  const std::string out = testing::ScratchDir() + "/out";
  const LabelSummary summary = RunLabelJob(MakeJob(out, RefineMode::kOff), s.Set(), {});
  EXPECT_EQ(summary.by_path.at("network"), 12);
  EXPECT_EQ(s.fitter.fits.load(), 0);
  EXPECT_FALSE(ReadLabelFile(LabelFilePath(out, "000001")).quality.Passed());
}

// The summary's motion metrics. The network's answer is 3 cm off on frame 5 alone
// (refine off: the answer is the label), so the errors' second differences are 30, 60
// and 30 mm on the triples centred on frames 4, 5 and 6 and 0 on the others; the
// unreadable frame 9 takes the triples centred on 8, 9 and 10 out: 120 mm over 7.
TEST(LabelJob, SummaryMotionMetricsCoverConsecutiveLabelledFramesOnly) {
  Stages s;
  s.predictor.shifted = {"000005"};
  s.capture.unreadable = {"000009"};
  const std::string out = testing::ScratchDir() + "/out";
  const JobConfig job = MakeJob(out, RefineMode::kOff);
  const LabelSummary summary = RunLabelJob(job, s.Set(), {});
  EXPECT_EQ(summary.failed, 1);
  for (const char* group : {"labels", "network", "network_raw"}) {
    const auto& metrics = summary.metrics.at(group);
    EXPECT_EQ(metrics.at("accel_error_mm").count, 7) << group;
    EXPECT_NEAR(metrics.at("accel_error_mm").Mean(), 120.0 / 7, 0.005) << group;
    // The test capture's poses are drawn independently per frame: they jump.
    EXPECT_GT(metrics.at("jitter_mm").Mean(), 10.0) << group;
  }
  EXPECT_THAT(summary.ToText(), HasSubstr("accel. error mm/f^2 17.14"));
  // The merge computes them again from the logs' keypoints.
  const LabelSummary merged = MergeLabelOutputs(
      out, "test", JobHash(job, s.predictor.weights_sha256), s.capture.FrameIds());
  EXPECT_NEAR(merged.metrics.at("labels").at("accel_error_mm").Mean(), 120.0 / 7, 0.005);
  EXPECT_EQ(merged.metrics.at("labels").at("jitter_mm").Mean(),
            summary.metrics.at("labels").at("jitter_mm").Mean());
}

TEST(LabelJob, AFailingFrameIsRecordedWithItsReasonAndTheJobGoesOn) {
  Stages s;
  s.capture.unreadable = {"000001"};
  s.predictor.throws = {"000004"};
  s.predictor.shifted = {"000009"};
  s.fitter.throws = {"000009"};
  const std::string out = testing::ScratchDir() + "/out";
  const LabelSummary summary =
      RunLabelJob(MakeJob(out, RefineMode::kFallback), s.Set(), {});
  EXPECT_EQ(summary.ok, 9);
  EXPECT_EQ(summary.failed, 3);
  std::map<std::string, std::string> reasons(summary.failures.begin(),
                                             summary.failures.end());
  EXPECT_THAT(reasons["000001"], HasSubstr("cannot read image"));
  EXPECT_THAT(reasons["000004"], HasSubstr("network exploded"));
  EXPECT_THAT(reasons["000009"], HasSubstr("solver diverged"));
  EXPECT_FALSE(fs::exists(LabelFilePath(out, "000004")));
  // The batch-mates of the throwing frame were predicted one by one and labelled.
  EXPECT_TRUE(fs::exists(LabelFilePath(out, "000003")));
  EXPECT_TRUE(fs::exists(LabelFilePath(out, "000005")));

  // A resumed run retries only the failed frames.
  s.capture.unreadable.clear();
  s.predictor.throws.clear();
  s.fitter.throws.clear();
  s.capture.loads = 0;
  LabelRunOptions resume;
  resume.resume = true;
  const LabelSummary again =
      RunLabelJob(MakeJob(out, RefineMode::kFallback), s.Set(), resume);
  EXPECT_EQ(s.capture.loads.load(), 3);
  EXPECT_EQ(again.ok, 12);
  EXPECT_EQ(again.skipped, 9);
}

TEST(LabelJob, InFallbackModeAFrameTheNetworkFailsOnIsFitFromFileEvidence) {
  Stages s;
  s.predictor.throws = {"000004"};
  const std::string scratch = testing::ScratchDir();
  const std::string out = scratch + "/out";
  JobConfig job = MakeJob(out, RefineMode::kFallback);
  job.keypoints = KeypointSource::kBoth;  // files where present, else the network's
  const LabelSummary summary = RunLabelJob(job, s.Set(), {});
  EXPECT_EQ(summary.ok, 12);
  EXPECT_EQ(summary.by_path.at("fallback_fit"), 1);
  const LabelRecord label = ReadLabelFile(LabelFilePath(out, "000004"));
  EXPECT_EQ(label.path, LabelPath::kFallbackFit);
  EXPECT_THAT(label.fit.at("why").get<std::string>(), HasSubstr("network exploded"));
  EXPECT_TRUE(label.quality.flags.empty());  // no network answer to check

  // refine off cannot fit: the frame fails with the network's reason.
  const std::string out_off = scratch + "/out_off";
  const LabelSummary off = RunLabelJob(MakeJob(out_off, RefineMode::kOff), s.Set(), {});
  EXPECT_EQ(off.failed, 1);
  EXPECT_THAT(off.failures.at(0).second, HasSubstr("network exploded"));
}

TEST(LabelJob, ResumeRedoesExactlyTheUnfinishedFramesAndGivesIdenticalLabels) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  const JobConfig job = MakeJob(out, RefineMode::kFallback);
  RunLabelJob(job, s.Set(), {});
  std::map<std::string, std::string> before;
  for (const std::string& f : s.capture.FrameIds())
    before[f] = testing::ReadFileBytes(LabelFilePath(out, f));

  // Simulate a crash: the log lost its last 4 records (one torn), two of those labels
  // never reached disk and a temporary was left behind.
  const std::string log_path = ShardLogPath(out, {0, 1});
  std::string log = testing::ReadFileBytes(log_path);
  for (int i = 0; i < 4; ++i) log.erase(log.rfind('\n', log.size() - 2) + 1);
  log += "{\"frame\": \"0000";
  std::ofstream(log_path, std::ios::binary | std::ios::trunc) << log;
  std::vector<std::string> lost;
  for (const auto& [frame, path] : LabelPaths(out)) lost.push_back(frame);
  ASSERT_EQ(lost.size(), 8u);
  std::vector<std::string> unfinished;
  for (const std::string& f : s.capture.FrameIds()) {
    if (!std::count(lost.begin(), lost.end(), f)) unfinished.push_back(f);
  }
  fs::remove(LabelFilePath(out, unfinished[0]));
  fs::remove(LabelFilePath(out, unfinished[1]));
  std::ofstream(LabelFilePath(out, unfinished[2]) + ".tmp.12345")
      << "{\"format\": \"hand";

  EXPECT_THROW(RunLabelJob(job, s.Set(), {}), InputError);  // neither resume nor force
  s.capture.loads = 0;
  LabelRunOptions resume;
  resume.resume = true;
  const LabelSummary summary = RunLabelJob(job, s.Set(), resume);
  EXPECT_EQ(s.capture.loads.load(), 4);
  EXPECT_EQ(summary.skipped, 8);
  EXPECT_EQ(summary.ok, 12);
  EXPECT_FALSE(fs::exists(LabelFilePath(out, unfinished[2]) + ".tmp.12345"));
  for (const auto& [frame, text] : before)
    EXPECT_EQ(testing::ReadFileBytes(LabelFilePath(out, frame)), text);

  // --force labels everything again.
  s.capture.loads = 0;
  LabelRunOptions force;
  force.force = true;
  RunLabelJob(job, s.Set(), force);
  EXPECT_EQ(s.capture.loads.load(), 12);
}

TEST(LabelJob, ShardsPartitionTheFramesAndTheirMergeEqualsOneProcess) {
  Stages s;
  s.predictor.shifted = {"000005"};
  const std::string root = testing::ScratchDir();
  RunLabelJob(MakeJob(root + "/single", RefineMode::kFallback), s.Set(), {});

  s.capture.loads = 0;
  const JobConfig sharded = MakeJob(root + "/sharded", RefineMode::kFallback);
  for (int i = 2; i >= 0; --i) {
    LabelRunOptions options;
    options.shard = {i, 3};
    const LabelSummary summary = RunLabelJob(sharded, s.Set(), options);
    EXPECT_EQ(summary.frames, 4);
  }
  EXPECT_EQ(s.capture.loads.load(), 12);  // every frame exactly once
  const std::vector<std::string> frames = s.capture.FrameIds();
  const std::string hash = JobHash(sharded, s.predictor.weights_sha256);
  const LabelSummary merged = MergeLabelOutputs(root + "/sharded", "test", hash, frames);
  EXPECT_EQ(merged.ok, 12);
  EXPECT_EQ(testing::ReadFileBytes(ManifestPath(root + "/sharded")),
            testing::ReadFileBytes(ManifestPath(root + "/single")));
  for (const std::string& f : frames) {
    EXPECT_EQ(testing::ReadFileBytes(LabelFilePath(root + "/sharded", f)),
              testing::ReadFileBytes(LabelFilePath(root + "/single", f)))
        << f;
  }
}

TEST(LabelJob, MergeReportsFramesNoShardHasLabelledYet) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  const JobConfig job = MakeJob(out, RefineMode::kFallback);
  LabelRunOptions options;
  options.shard = {1, 4};
  RunLabelJob(job, s.Set(), options);
  std::vector<std::string> not_labelled;
  const LabelSummary merged =
      MergeLabelOutputs(out, "test", JobHash(job, s.predictor.weights_sha256),
                        s.capture.FrameIds(), "", &not_labelled);
  EXPECT_EQ(merged.ok, 3);
  EXPECT_EQ(merged.missing, 9);
  ASSERT_EQ(not_labelled.size(), 9u);
  EXPECT_EQ(not_labelled[0], "000000 (not yet run)");
}

TEST(LabelJob, RefusesAnOutputFolderOfAnotherJob) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  RunLabelJob(MakeJob(out, RefineMode::kFallback), s.Set(), {});
  JobConfig other = MakeJob(out, RefineMode::kFallback);
  other.seed = 6;
  LabelRunOptions resume;
  resume.resume = true;
  try {
    RunLabelJob(other, s.Set(), resume);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("job.json"));
    EXPECT_THAT(e.what(), HasSubstr("different job"));
  }
}

TEST(LabelJob, SelectFramesByRangeAndIds) {
  const std::vector<std::string> all = {"a", "b", "c", "d"};
  EXPECT_EQ(SelectFrames(all, "all", "j"), all);
  EXPECT_EQ(SelectFrames(all, "1:3", "j"), (std::vector<std::string>{"b", "c"}));
  EXPECT_EQ(SelectFrames(all, ":2", "j"), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(SelectFrames(all, "d, b", "j"), (std::vector<std::string>{"b", "d"}));
  EXPECT_THROW(SelectFrames(all, "2:9", "j"), InputError);
  EXPECT_THROW(SelectFrames(all, "x", "j"), InputError);
}

TEST(LabelJob, JobHashIgnoresWhereOutputsGoButNotWhatChangesLabels) {
  JobConfig a = MakeJob("/tmp/a", RefineMode::kFallback);
  JobConfig b = MakeJob("/tmp/b", RefineMode::kFallback);
  b.threads = 1;
  b.batch_size = 8;
  EXPECT_EQ(JobHash(a, "w"), JobHash(b, "w"));
  EXPECT_NE(JobHash(a, "w"), JobHash(a, "v"));
  b.quality.max_reprojection_px = 3;
  EXPECT_NE(JobHash(a, "w"), JobHash(b, "w"));
  // How answers are read matters only with a network.
  JobConfig c = a;
  c.network_keypoints = AnswerKeypoints::kJoints;
  EXPECT_NE(JobHash(a, "w"), JobHash(c, "w"));
  EXPECT_EQ(JobHash(a, ""), JobHash(c, ""));
  // So does the network's arithmetic (fp32, the default, keeps older jobs' hash).
  JobConfig d = a;
  d.network_precision = "bf16";
  EXPECT_NE(JobHash(a, "w"), JobHash(d, "w"));
  EXPECT_EQ(JobHash(a, ""), JobHash(d, ""));
}

// The fields `handlabel fit` brought into the job change the hash only when set, so a
// job that does not use them keeps the hash it had before they existed.
TEST(LabelJob, JobHashCoversTheFitFieldsOnlyWhenSet) {
  JobConfig a = MakeJob("/tmp/a", RefineMode::kFallback);
  // How answers were read before network.keypoints existed.
  a.network_keypoints = AnswerKeypoints::kJoints;
  const std::string plain = JobHash(a, "w");
  // The hash of such a job before the fields existed (computed as JobHash did then).
  const QualityThresholds& q = a.quality;
  const nlohmann::json before = {
      {"label_format", kLabelFormatVersion},
      {"input", {a.input_format, a.input_path, a.frames}},
      {"cameras", {a.cameras_source, a.cameras_file}},
      {"hand_model", a.hand_model},
      {"weights_sha256", "w"},
      {"refine",
       {ToString(a.refine_mode), q.max_reprojection_px, q.max_view_disagreement_mm,
        q.min_confidence, q.min_views, q.min_hand_span_m, q.max_hand_span_m}},
      {"evidence", {static_cast<int>(a.keypoints), static_cast<int>(a.masks)}},
      {"seed", a.seed}};
  EXPECT_EQ(plain, Sha256Hex(before.dump()));
  for (const auto& change : std::vector<std::function<void(JobConfig*)>>{
           [](JobConfig* j) { j->fit.init = "gt"; },
           [](JobConfig* j) { j->fit.keypoint_loss = "huber"; },
           [](JobConfig* j) { j->fit.joint_limits = false; },
           [](JobConfig* j) { j->keypoint_files = "keypoints"; },
           [](JobConfig* j) { j->ignore_views = {"cam1"}; },
           [](JobConfig* j) { j->max_frames = 3; },
           // Today's default reads answers otherwise: older labels must not resume.
           [](JobConfig* j) { j->network_keypoints = AnswerKeypoints::kMean; }}) {
    JobConfig b = a;
    change(&b);
    EXPECT_NE(JobHash(b, "w"), plain);
  }
}

// A label file cut short after its record was logged (disk full, a copy interrupted):
// resume labels it again and merge reports it instead of counting it as done.
TEST(LabelJob, TruncatedLabelIsRedoneOnResumeAndReportedByMerge) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  const JobConfig job = MakeJob(out, RefineMode::kFallback);
  RunLabelJob(job, s.Set(), {});
  const std::string label = LabelFilePath(out, "000004");
  const std::string full = testing::ReadFileBytes(label);
  fs::resize_file(label, full.size() / 2);
  const std::string hash = JobHash(job, s.predictor.weights_sha256);
  std::vector<std::string> not_labelled;
  const LabelSummary merged =
      MergeLabelOutputs(out, "test", hash, s.capture.FrameIds(), "", &not_labelled);
  EXPECT_EQ(merged.ok, 11);
  ASSERT_EQ(not_labelled.size(), 1u);
  EXPECT_THAT(not_labelled[0], HasSubstr("000004"));
  EXPECT_THAT(not_labelled[0], HasSubstr("truncated"));
  // Same size, other content: caught by the checksum.
  std::string edited = full;
  edited[edited.size() / 2] = edited[edited.size() / 2] == '1' ? '2' : '1';
  std::ofstream(LabelFilePath(out, "000007"), std::ios::binary | std::ios::trunc)
      << edited;

  s.capture.loads = 0;
  LabelRunOptions resume;
  resume.resume = true;
  const LabelSummary summary = RunLabelJob(job, s.Set(), resume);
  EXPECT_EQ(s.capture.loads.load(), 2);
  EXPECT_EQ(summary.ok, 12);
  EXPECT_EQ(testing::ReadFileBytes(label), full);
  EXPECT_TRUE(
      LabelFileProblem(FrameLog(ShardLogPath(out, {0, 1})).Latest()[4], label).empty());
}

// merge with another job's file: refused before the manifest is touched.
TEST(LabelJob, MergeRefusesAnotherJobWithoutTouchingTheManifest) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  const JobConfig job = MakeJob(out, RefineMode::kFallback);
  RunLabelJob(job, s.Set(), {});
  const std::string manifest = testing::ReadFileBytes(ManifestPath(out));
  JobConfig other = job;
  other.seed = 9;
  const std::string error = testing::InputErrorOf([&] {
    MergeLabelOutputs(out, "other", JobHash(other, "w"), s.capture.FrameIds());
  });
  EXPECT_THAT(error, HasSubstr("job.json"));
  EXPECT_THAT(error, HasSubstr("another job"));
  EXPECT_EQ(testing::ReadFileBytes(ManifestPath(out)), manifest);
  // A record of another job in a shard log (the stamp says this job) is refused too.
  const std::string hash = JobHash(job, s.predictor.weights_sha256);
  FrameLog foreign(ShardLogPath(out, {1, 2}));
  FrameRecord r;
  r.frame = "000003";
  r.status = "ok";
  r.job_hash = JobHash(other, "w");
  foreign.Record(r);
  const std::string record_error = testing::InputErrorOf(
      [&] { MergeLabelOutputs(out, "test", hash, s.capture.FrameIds()); });
  EXPECT_THAT(record_error, HasSubstr("shard-00001-of-00002.jsonl"));
  EXPECT_THAT(record_error, HasSubstr("000003"));
  EXPECT_EQ(testing::ReadFileBytes(ManifestPath(out)), manifest);
}

// --force with another job replaces the stamp and drops every old record, so the new
// job's resume never counts the old job's labels as its own.
TEST(LabelJob, ForceWithAnotherJobDropsTheOldRecords) {
  Stages s;
  const std::string out = testing::ScratchDir() + "/out";
  JobConfig job = MakeJob(out, RefineMode::kFallback);
  LabelRunOptions half;
  half.shard = {0, 2};
  RunLabelJob(job, s.Set(), half);
  JobConfig other = job;
  other.seed = 9;
  LabelRunOptions force;
  force.force = true;
  force.shard = {1, 2};
  RunLabelJob(other, s.Set(), force);
  EXPECT_FALSE(fs::exists(ShardLogPath(out, {0, 2})));
  LabelRunOptions resume;
  resume.resume = true;
  resume.shard = {0, 2};
  s.capture.loads = 0;
  RunLabelJob(other, s.Set(), resume);
  EXPECT_EQ(s.capture.loads.load(), 6);  // shard 0 labelled again for the new job
  const LabelSummary merged = MergeLabelOutputs(
      out, "test", JobHash(other, s.predictor.weights_sha256), s.capture.FrameIds());
  EXPECT_EQ(merged.ok, 12);
}

TEST(LabelJob, FrameListedTwiceIsRefused) {
  const std::vector<std::string> all = {"a", "b", "c"};
  const std::string error =
      testing::InputErrorOf([&] { SelectFrames(all, "a,b,a", "job.yaml"); });
  EXPECT_THAT(error, HasSubstr("job.yaml"));
  EXPECT_THAT(error, HasSubstr("input.frames"));
  EXPECT_THAT(error, HasSubstr("'a' listed twice"));
  Stages s;
  s.capture.duplicate = "000003";
  const std::string out = testing::ScratchDir() + "/out";
  const std::string run_error = testing::InputErrorOf(
      [&] { RunLabelJob(MakeJob(out, RefineMode::kFallback), s.Set(), {}); });
  EXPECT_THAT(run_error, HasSubstr("'000003' listed twice"));
  EXPECT_FALSE(fs::exists(ShardLogPath(out, {0, 1})));
}

}  // namespace
}  // namespace handlabel
