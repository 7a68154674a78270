// Label jobs over the dataset readers in place (input.format dexycb, ho3d, oakink): the
// job file selects the reader and a whole job runs over a fixture in the dataset's
// layout.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/capsule_hand.h"
#include "core/errors.h"
#include "core/image_file.h"
#include "pipeline/label_job.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stage_factory.h"
#include "tests/capture/dexycb_fixture.h"
#include "tests/capture/ho3d_fixture.h"
#include "tests/capture/oakink_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;
using namespace testing;  // the fixtures

// DexYCB frame ids name subject, sequence and frame; their label files are file-name
// safe.
TEST(DexYcbJob, LabelFileNamesOfSequenceFrameIds) {
  EXPECT_EQ(LabelFilePath("out", "20200709-subject-01/20200709_142123/000000"),
            "out/labels/20200709-subject-01__20200709_142123__000000.json");
}

// The whole job from a YAML file: fit-only from the labels' 2D keypoints, evaluated
// against their joint_3d, overlays drawn on the JPEGs.
TEST(DexYcbJob, LabelJobFitsTheLabelsKeypointsAndEvaluatesAgainstJoint3d) {
  const std::string dir = testing::ScratchDir();
  const DexYcbFixture fx =
      WriteDexYcbFixture(dir + "/dexycb", MakeCapsuleHand(HandSide::kRight));
  std::ofstream(dir + "/job.yaml") << R"(name: dexycb-test
hand_model: capsule
input:
  format: dexycb
  path: dexycb/20200709-subject-01/20200709_141754
network:
  threads: 1
refine:
  mode: always
evidence:
  keypoints_2d: files
  masks: none
output:
  dir: out
)";
  const JobConfig job = LoadJobConfig(dir + "/job.yaml");
  // The shipped example is a valid job of the same kind.
  const JobConfig example =
      LoadJobConfig(std::string(HANDLABEL_SOURCE_DIR) + "/jobs/dexycb.yaml");
  EXPECT_EQ(example.input_format, "dexycb");
  EXPECT_EQ(example.keypoints, KeypointSource::kFiles);
  const BuiltLabelStages built = BuildLabelStages(job);
  EXPECT_THAT(built.source->Describe(), HasSubstr("DexYCB"));
  const LabelSummary summary = RunLabelJob(job, built.Set(), {});
  EXPECT_EQ(summary.ok, 3);
  EXPECT_EQ(summary.failed, 0);
  // The capsule hand rendered the fixture, so the fit can reach the truth.
  const double mpjpe_mm = summary.metrics.at("labels").at("mpjpe_mm").Mean();
  RecordProperty("mpjpe_um", static_cast<int>(1000 * mpjpe_mm));
  EXPECT_LT(mpjpe_mm, 5.0);
  EXPECT_EQ(summary.metrics.at("labels").count("mpvpe_mm"), 0u);  // no truth vertices
  const LabelRecord label = ReadLabelFile(LabelFilePath(dir + "/out", "000001"));
  EXPECT_EQ(label.path, LabelPath::kFallbackFit);
  const ImageU8 overlay = ReadPng(OverlayPath(dir + "/out", "000001", fx.rig[0].name));
  EXPECT_EQ(overlay.width, 160);
  // Drawn on the camera's image, not on the grey stand-in for a missing one.
  const ImageU8 image =
      ReadJpeg(fx.sequence + "/" + fx.rig[0].name + "/color_000001.jpg");
  int same = 0;
  for (size_t i = 0; i < image.data.size(); ++i) same += overlay.data[i] == image.data[i];
  EXPECT_GT(same, static_cast<int>(image.data.size() / 2));
}

// The frame source that a minimal job file with input.format and input.path selects.
std::unique_ptr<FrameSource> SourceOfJob(const std::string& dir,
                                         const std::string& format,
                                         const std::string& path) {
  std::ofstream(dir + "/job.yaml")
      << "input:\n  format: " << format << "\n  path: " << path
      << "\nnetwork:\n  weights: poem.pt\noutput:\n  dir: out\n";
  return BuildFrameSource(LoadJobConfig(dir + "/job.yaml"));
}

TEST(Ho3dJob, JobFileSelectsIt) {
  const Ho3dFixture fx = WriteHo3dFixture(testing::ScratchDir(), 1);
  const auto source = SourceOfJob(fx.root, "ho3d", "train/ABF1");
  EXPECT_THAT(source->Describe(), HasSubstr("HO3D v3"));
  EXPECT_EQ(source->FrameIds(), std::vector<std::string>{"0000"});
}

TEST(OakInkJob, JobFileSelectsIt) {
  const OakInkFixture fx = WriteOakInkFixture(testing::ScratchDir(), 1);
  const auto source = SourceOfJob(fx.image_dir + "/..", "oakink", "image");
  EXPECT_THAT(source->Describe(), HasSubstr("OakInk"));
  EXPECT_EQ(source->FrameIds(), fx.ids);
}

}  // namespace
}  // namespace handlabel
