#include "exports/label_series.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

LabelRecord Label(const std::string& frame, HandSide side, const std::string& model) {
  LabelRecord label;
  label.frame = frame;
  label.side = side;
  label.path = LabelPath::kFallbackFit;
  label.mesh.keypoints = Points3d::Zero(kNumHandKeypoints, 3);
  label.mesh.joints = Points3d::Zero(kNumHandJoints, 3);
  label.mesh.vertices = Points3d::Zero(4, 3);
  label.provenance.hand_model = model;
  return label;
}

TEST(LabelSeries, ReadsAJobFolderInFrameOrderAndSkipsTemporaries) {
  const std::string dir = testing::ScratchDir();
  for (const std::string frame : {"f2", "f10", "f1"}) {
    WriteLabelFiles(dir, Label(frame, HandSide::kLeft, "MANO_LEFT"), Faces(), {});
  }
  WriteFileAtomically(dir + "/labels/f3.json.tmp.123", "{half");
  for (const std::string& folder : {dir, dir + "/labels"}) {
    const LabelSeries series = ReadLabelSeries(folder);
    ASSERT_EQ(series.labels.size(), 3u);
    EXPECT_EQ(series.labels[0].frame, "f1");
    EXPECT_EQ(series.labels[1].frame, "f10");  // the capture's order: sorted ids
    EXPECT_EQ(series.labels[2].frame, "f2");
    EXPECT_EQ(series.side, HandSide::kLeft);
    EXPECT_EQ(series.hand_model, "MANO_LEFT");
  }
}

TEST(LabelSeries, OneHandAndOneModelPerSeries) {
  const std::string dir = testing::ScratchDir();
  WriteLabelFiles(dir, Label("a", HandSide::kRight, "m"), Faces(), {});
  WriteLabelFiles(dir, Label("b", HandSide::kLeft, "m"), Faces(), {});
  std::string message = testing::InputErrorOf([&] { ReadLabelSeries(dir); });
  EXPECT_NE(message.find("b.json"), std::string::npos) << message;
  EXPECT_NE(message.find("hand_side"), std::string::npos) << message;
  WriteLabelFiles(dir, Label("b", HandSide::kRight, "other"), Faces(), {});
  message = testing::InputErrorOf([&] { ReadLabelSeries(dir); });
  EXPECT_NE(message.find("provenance.hand_model"), std::string::npos) << message;
  const std::string empty = testing::ScratchDir();
  message = testing::InputErrorOf([&] { ReadLabelSeries(empty); });
  EXPECT_NE(message.find("label files"), std::string::npos) << message;
}

}  // namespace
}  // namespace handlabel
