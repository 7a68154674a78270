#include "pipeline/label_summary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pipeline/frame_metrics.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

std::string Id(int f) {
  char id[16];
  std::snprintf(id, sizeof(id), "%06d", f);
  return id;
}

// 21 keypoints at one point, in the frame log's millimetres.
std::vector<double> AllAt(double x, double y, double z) {
  std::vector<double> mm;
  for (int k = 0; k < kNumHandKeypoints; ++k) mm.insert(mm.end(), {x, y, z});
  return mm;
}

// Frames 0..7: the truth accelerates by 1 mm/frame^2 along y; the labels are the truth
// but 2 mm off along x on frame 3; frame 6 failed. The labels' errors then have second
// differences of 2, 4 and 2 mm on the triples centred on frames 2, 3 and 4, and only
// the triples centred on 1..4 have three labelled frames.
std::map<std::string, FrameRecord> Records() {
  std::map<std::string, FrameRecord> records;
  for (int f = 0; f < 8; ++f) {
    FrameRecord r;
    r.frame = Id(f);
    r.status = f == 6 ? "failed" : "ok";
    r.path = "fallback_fit";
    if (f != 6) {
      const double y = 0.5 * f * f;
      r.keypoints_mm[kTruthKeypoints] = AllAt(0, y, 100);
      r.keypoints_mm["labels"] = AllAt(f == 3 ? 2 : 0, y, 100);
      r.metrics["labels/mpjpe_mm"] = f == 3 ? 2 : 0;
    }
    records[r.frame] = r;
  }
  return records;
}

std::vector<std::string> Ids(std::initializer_list<int> frames) {
  std::vector<std::string> ids;
  for (int f : frames) ids.push_back(Id(f));
  return ids;
}

TEST(LabelSummary, MotionMetricsOverTriplesOfConsecutiveLabelledFrames) {
  const LabelSummary s = Summarize(Ids({0, 1, 2, 3, 4, 5, 6, 7}), Records());
  const auto& labels = s.metrics.at("labels");
  EXPECT_EQ(labels.at("accel_error_mm").count, 4);
  EXPECT_NEAR(labels.at("accel_error_mm").Mean(), (2 + 4 + 2) / 4.0, 1e-9);
  // The labels' accelerations: (0, 1, 0), (2, 1, 0), (-4, 1, 0), (2, 1, 0) mm/frame^2.
  EXPECT_NEAR(labels.at("jitter_mm").Mean(),
              (1 + 2 * std::sqrt(5.0) + std::sqrt(17.0)) / 4, 1e-9);
  EXPECT_EQ(s.metrics.count(kTruthKeypoints), 0u);  // not a group
  EXPECT_NEAR(s.ToJson()["metrics"]["labels"]["accel_error_mm"].get<double>(), 2.0, 1e-9);
  EXPECT_EQ(s.ToJson()["metrics"]["labels"]["frames"], 7);
  EXPECT_THAT(s.ToText(), HasSubstr("accel. error mm/f^2 2.00 jitter mm/f^2 2.40"));
}

TEST(LabelSummary, MotionMetricsNeverDifferenceAcrossAGapInTheFrameIds) {
  // Without frame 2 in the job (input.frames left it out) only the triple centred on
  // frame 4 remains of the labelled frames 0 1 3 4 5: 2 mm.
  const LabelSummary s = Summarize(Ids({0, 1, 3, 4, 5}), Records());
  EXPECT_EQ(s.metrics.at("labels").at("accel_error_mm").count, 1);
  EXPECT_NEAR(s.metrics.at("labels").at("accel_error_mm").Mean(), 2.0, 1e-9);
  // Fewer than three consecutive frames: no motion metrics at all.
  const LabelSummary two = Summarize(Ids({0, 1, 3}), Records());
  EXPECT_EQ(two.metrics.at("labels").count("accel_error_mm"), 0u);
  EXPECT_THAT(two.ToText(), ::testing::Not(HasSubstr("jitter")));
}

}  // namespace
}  // namespace handlabel
