// `handlabel label` on a dataset read in place: a DexYCB-layout fixture (JPEG images,
// labels_*.npz) through the POEM network (tiny, random weights: the plumbing is under
// test), the quality checks, the fallback fit on the labels' 2D keypoints, overlays.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hand/capsule_hand.h"
#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/poem_config.h"
#include "pipeline/label_outputs.h"
#include "pipeline/label_record.h"
#include "tests/apps/run_command.h"
#include "tests/capture/dexycb_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

TEST(LabelDataset, DexYcbSequenceThroughTheNetworkAndTheFallbackFit) {
  const std::string dir = testing::ScratchDir();
  testing::DexYcbFixtureOptions o;
  o.num_frames = 2;
  const testing::DexYcbFixture fx =
      testing::WriteDexYcbFixture(dir + "/dexycb", MakeCapsuleHand(HandSide::kRight), o);
  WriteRandomPoemCheckpoint(PoemConfigByName("tiny", 4), 4, dir + "/tiny.pt");
  std::ofstream(dir + "/job.yaml")
      << "name: dex\nhand_model: capsule\n"
      << "input: {format: dexycb, path: dexycb/20200709-subject-01/20200709_141754}\n"
      << "network: {weights: tiny.pt, threads: 1, batch_size: 2}\n"
      << "refine: {mode: fallback}\n"
      << "evidence: {keypoints_2d: both, masks: none}\n"
      << "output: {dir: out}\n";
  const auto r = testing::RunHandlabelCommand({"label", "--job", dir + "/job.yaml"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("input: DexYCB"));
  // The network read the JPEGs of every frame; random weights fail the checks, so the
  // labels are fits to the labels files' keypoints.
  EXPECT_THAT(r.err, HasSubstr("network_raw (2 frames)"));
  EXPECT_THAT(r.err, HasSubstr("2 labelled (fallback_fit 2)"));
  const LabelRecord label = ReadLabelFile(LabelFilePath(dir + "/out", "000001"));
  EXPECT_EQ(label.path, LabelPath::kFallbackFit);
  // Fits to the labels files' 2D (the capsule hand drew them), not to the random
  // network's: they land on the fixture's joint_3d.
  const nlohmann::json summary =
      nlohmann::json::parse(testing::ReadFileBytes(dir + "/out/summary.json"));
  EXPECT_LT(summary.at("metrics").at("labels").at("mpjpe_mm").get<double>(), 5.0);
  EXPECT_TRUE(std::filesystem::exists(
      OverlayPath(dir + "/out", "000001", fx.rig[3].name, "jpg")));
  EXPECT_EQ(testing::RunHandlabelCommand({"merge", "--job", dir + "/job.yaml"}).status,
            0);
}

}  // namespace
}  // namespace handlabel
