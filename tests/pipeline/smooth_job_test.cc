// The smoothing pass of a labelled sequence (pipeline/smooth_job.h): the windows'
// layout and blend, and end to end on a small synthetic sequence (capsule hand, 160x120
// DexYCB-like rig, simulated detections): smoothed labels beside the per-frame ones,
// the same bits for 1 and 2 threads and for two shards, resumable, and per-frame labels
// unchanged by the `sequence` section.

#include "pipeline/smooth_job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/synth_capture.h"
#include "hand/capsule_hand.h"
#include "pipeline/label_job.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stage_factory.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

namespace fs = std::filesystem;

TEST(SegmentWindows, CoverTheSegmentWithFullWindowsThatOverlap) {
  for (int length : {1, 5, 48, 49, 100, 130, 301}) {
    const std::vector<WindowSpan> spans = SegmentWindows(length, 48, 16);
    std::vector<int> covered(length, 0);
    for (const WindowSpan& s : spans) {
      EXPECT_EQ(s.end - s.begin, std::min(length, 48)) << length;
      for (int i = s.begin; i < s.end; ++i) ++covered[i];
    }
    EXPECT_EQ(spans.front().begin, 0);
    EXPECT_EQ(spans.back().end, length);
    for (size_t w = 1; w < spans.size(); ++w) {
      EXPECT_GE(spans[w - 1].end - spans[w].begin, 16) << length;  // overlap
    }
    for (int i = 0; i < length; ++i) EXPECT_GE(covered[i], 1) << length << " " << i;
  }
}

TEST(BlendWeight, BlendIsContinuousAcrossTheOverlap) {
  // Two windows solved to different translations: the blend moves from one to the other
  // in steps of at most the difference / (overlap + 1), with no jump at either end.
  const int length = 100, overlap = 16;
  const std::vector<WindowSpan> spans = SegmentWindows(length, 48, overlap);
  ASSERT_GE(spans.size(), 2u);
  HandParams a, b;
  a.betas = b.betas = Eigen::VectorXd::Zero(10);
  a.global_orient = Eigen::Vector3d(0.1, 0.2, 0.3);
  b.global_orient = Eigen::Vector3d(0.1, 0.2, 0.3);
  b.transl = Eigen::Vector3d(0.017, 0, 0);
  double previous = 0, largest_step = 0;
  for (int i = 0; i < spans[1].end; ++i) {
    std::vector<std::pair<double, HandParams>> weighted;
    if (i < spans[0].end)
      weighted.emplace_back(BlendWeight(spans[0], i, length, overlap), a);
    if (i >= spans[1].begin) {
      weighted.emplace_back(BlendWeight(spans[1], i, length, overlap), b);
    }
    const HandParams blended = BlendParams(weighted);
    if (i > 0)
      largest_step = std::max(largest_step, std::abs(blended.transl.x() - previous));
    previous = blended.transl.x();
    EXPECT_NEAR((blended.global_orient - a.global_orient).norm(), 0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(previous, 0.017);  // past the overlap: the second window alone
  EXPECT_LE(largest_step, 0.017 / (overlap + 1) + 1e-12);
}

// A labelled synthetic sequence: capture, job file (with `sequence_yaml` appended) and
// the per-frame labels of a whole-job run.
struct LabelledSequence {
  std::string capture, job_file, out;
};

std::string WriteSequenceCapture(const std::string& dir, int frames) {
  SynthCaptureOptions o;
  o.rig.preset = "dexycb";
  o.rig.width = 160;
  o.rig.height = 120;
  o.num_frames = frames;
  o.seed = 45;
  o.num_threads = 1;
  o.sequence.enabled = true;
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, dir, "builtin:capsule");
  return dir;
}

LabelledSequence LabelSequence(const std::string& scratch, const std::string& capture,
                               const std::string& name,
                               const std::string& sequence_yaml) {
  LabelledSequence s;
  s.capture = capture;
  s.out = scratch + "/" + name;
  s.job_file = scratch + "/" + name + ".yaml";
  std::ofstream(s.job_file) << "name: seq\nseed: 3\nhand_model: capsule\n"
                            << "input: {format: native, path: " << capture << "}\n"
                            << "network: {threads: 2}\n"
                            << "refine: {mode: always}\n"
                            << "evidence: {keypoints_2d: files, masks: none}\n"
                            << "output: {dir: " << s.out << ", overlays: false}\n"
                            << sequence_yaml;
  const JobConfig job = LoadJobConfig(s.job_file);
  const BuiltLabelStages stages = BuildLabelStages(job);
  RunLabelJob(job, stages.Set(), {});
  return s;
}

std::map<std::string, std::string> SmoothedLabels(const std::string& out) {
  std::map<std::string, std::string> labels;
  for (const auto& e : fs::directory_iterator(SmoothedOutputDir(out) + "/labels")) {
    labels[e.path().filename().string()] = testing::ReadFileBytes(e.path().string());
  }
  return labels;
}

class SmoothJobTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // The suite's own folder (ScratchDir needs a running test); removed at the end.
    scratch_ = new std::string((fs::temp_directory_path() /
                                ("handlabel_SmoothJobTest_" + std::to_string(::getpid())))
                                   .string());
    fs::remove_all(*scratch_);
    fs::create_directories(*scratch_);
    const std::string capture = WriteSequenceCapture(*scratch_ + "/capture", 20);
    sequence_ = new LabelledSequence(LabelSequence(
        *scratch_, capture, "job",
        "sequence: {smooth: true, window: 8, overlap: 3, acceleration_sigma_mm: 0.3}\n"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*scratch_);
    delete sequence_;
    delete scratch_;
  }
  static JobConfig Job(int threads) {
    JobConfig job = LoadJobConfig(sequence_->job_file);
    job.threads = threads;
    return job;
  }

  static std::string* scratch_;
  static LabelledSequence* sequence_;
};
std::string* SmoothJobTest::scratch_ = nullptr;
LabelledSequence* SmoothJobTest::sequence_ = nullptr;

TEST_F(SmoothJobTest, SmoothsBesideThePerFrameLabelsAndReportsMotion) {
  const std::string labels_before =
      testing::ReadFileBytes(LabelFilePath(sequence_->out, "000007"));
  SmoothRunOptions options;
  options.force = true;
  const SmoothSummary s = RunSmoothJob(Job(1), options);
  EXPECT_EQ(s.frames, 20);
  EXPECT_EQ(s.smoothed, 20);
  EXPECT_EQ(s.windows, 4);  // 0-8, 5-13, 10-18, 12-20
  EXPECT_EQ(testing::ReadFileBytes(LabelFilePath(sequence_->out, "000007")),
            labels_before);
  const LabelRecord smoothed =
      ReadLabelFile(LabelFilePath(SmoothedOutputDir(sequence_->out), "000007"));
  const LabelRecord per_frame = ReadLabelFile(LabelFilePath(sequence_->out, "000007"));
  EXPECT_NE(smoothed.mesh.keypoints, per_frame.mesh.keypoints);
  ASSERT_TRUE(smoothed.fit.contains("smoothing"));
  ASSERT_FALSE(s.report.is_null());
  const nlohmann::json& before = s.report.at("per_frame");
  const nlohmann::json& after = s.report.at("smoothed_labels");
  EXPECT_LT(after.at("jitter_mm").get<double>(), before.at("jitter_mm").get<double>());
  EXPECT_LT(after.at("accel_error_mm").get<double>(),
            before.at("accel_error_mm").get<double>());
  EXPECT_LT(after.at("mpjpe_mm").get<double>(),
            before.at("mpjpe_mm").get<double>() + 0.5);
  EXPECT_TRUE(fs::exists(SmoothedOutputDir(sequence_->out) + "/summary.json"));
}

TEST_F(SmoothJobTest, SameLabelsAtOneAndTwoThreadsAndInShards) {
  SmoothRunOptions options;
  options.force = true;
  RunSmoothJob(Job(1), options);
  const auto one_thread = SmoothedLabels(sequence_->out);
  RunSmoothJob(Job(2), options);
  EXPECT_EQ(SmoothedLabels(sequence_->out), one_thread);
  fs::remove_all(SmoothedOutputDir(sequence_->out));
  for (int shard = 0; shard < 2; ++shard) {
    SmoothRunOptions part;
    part.shard = {shard, 2};
    const SmoothSummary s = RunSmoothJob(Job(2), part);
    EXPECT_EQ(s.frames, 10);
    EXPECT_EQ(s.report.is_null(), shard == 0);  // the summary once every frame is done
  }
  EXPECT_EQ(SmoothedLabels(sequence_->out), one_thread);
}

TEST_F(SmoothJobTest, ResumeSmoothsOnlyWhatIsMissing) {
  SmoothRunOptions options;
  options.force = true;
  RunSmoothJob(Job(2), options);
  const auto all = SmoothedLabels(sequence_->out);
  fs::remove(LabelFilePath(SmoothedOutputDir(sequence_->out), "000011"));
  const SmoothSummary s = RunSmoothJob(Job(2), {});
  EXPECT_EQ(s.smoothed, 1);
  EXPECT_EQ(s.skipped, 19);
  EXPECT_EQ(s.windows, 2);  // the two windows covering frame 11
  EXPECT_EQ(SmoothedLabels(sequence_->out), all);
}

TEST_F(SmoothJobTest, PerFrameLabelsDoNotDependOnTheSequenceSection) {
  // The same job without the section labels the same bytes (the section changes
  // neither the fits nor the job hash).
  const LabelledSequence plain =
      LabelSequence(*scratch_, sequence_->capture, "plain", "");
  for (const std::string frame : {"000000", "000010", "000019"}) {
    EXPECT_EQ(testing::ReadFileBytes(LabelFilePath(plain.out, frame)),
              testing::ReadFileBytes(LabelFilePath(sequence_->out, frame)));
  }
  EXPECT_FALSE(fs::exists(SmoothedOutputDir(plain.out)));
}

// smoothed/ holds one smoothing: other settings, or a stamp that does not parse, are
// refused naming smoothing.json (--force replaces them), before anything is solved.
TEST_F(SmoothJobTest, RefusesOtherSettingsAndABrokenStampUnlessForced) {
  // The last frame's shard (two windows, not twenty frames) stamps the folder with the
  // fixture's settings, or finds it stamped.
  SmoothRunOptions last_frame;
  last_frame.shard = {19, 20};
  RunSmoothJob(Job(1), last_frame);
  const std::string stamp_path = SmoothedOutputDir(sequence_->out) + "/smoothing.json";
  const std::string stamp = testing::ReadFileBytes(stamp_path);
  ASSERT_FALSE(stamp.empty());
  JobConfig other = Job(1);
  other.sequence.acceleration_sigma_mm = 2.0;
  EXPECT_THAT(testing::InputErrorOf([&] { RunSmoothJob(other, {}); }),
              HasSubstr("smoothing.json"));
  std::ofstream(stamp_path) << "{bad";
  EXPECT_THAT(testing::InputErrorOf([&] { RunSmoothJob(Job(1), {}); }),
              HasSubstr("not valid JSON"));
  std::ofstream(stamp_path) << stamp;                 // as the fixture left it
  EXPECT_NO_THROW(RunSmoothJob(Job(1), last_frame));  // the fixture's stamp again
}

TEST_F(SmoothJobTest, RefusesEvidenceThatIsNotOnDisk) {
  JobConfig job = Job(1);
  job.keypoints = KeypointSource::kNetwork;
  try {
    RunSmoothJob(job, {});
    FAIL() << "expected an InputError";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("evidence.keypoints_2d"), std::string::npos);
  }
}

// sequence.detector_keypoints: a file that is not there is refused naming the field; the
// shipped MediaPipe model is the open hand's (778 vertices), not the capsule hand's.
TEST_F(SmoothJobTest, RefusesADetectorKeypointModelThatIsMissingOrOfAnotherTopology) {
  JobConfig job = Job(1);
  job.sequence.detector_keypoints = *scratch_ + "/no_such_model.json";
  EXPECT_THAT(testing::InputErrorOf([&] { RunSmoothJob(job, {}); }),
              HasSubstr("sequence.detector_keypoints"));
  job.sequence.detector_keypoints = "mediapipe";
  EXPECT_THAT(testing::InputErrorOf([&] { RunSmoothJob(job, {}); }),
              HasSubstr("num_vertices"));
}

}  // namespace
}  // namespace handlabel
