#include "pipeline/frame_metrics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::ElementsAre;

TEST(MotionFrameNumbers, NeighboursCountingUpByOneAreConsecutive) {
  EXPECT_THAT(MotionFrameNumbers({"000041", "000042", "000043"}), ElementsAre(0, 1, 2));
  EXPECT_THAT(MotionFrameNumbers({"a/cam/9", "a/cam/10", "a/cam/11"}),
              ElementsAre(0, 1, 2));
  EXPECT_TRUE(MotionFrameNumbers({}).empty());
}

TEST(MotionFrameNumbers, SkippedFramesOtherRecordingsAndBareIdsAreGaps) {
  // 000003 is missing (a job's frame selection): 2 and 4 are not neighbours in time.
  EXPECT_THAT(MotionFrameNumbers({"000001", "000002", "000004", "000005"}),
              ElementsAre(0, 1, 3, 4));
  // Another recording's frame 1 does not follow this one's frame 0.
  EXPECT_THAT(MotionFrameNumbers({"s1/000000", "s2/000001", "s2/000002"}),
              ElementsAre(0, 2, 3));
  // Ids without a trailing number say nothing about time; nor does counting down.
  EXPECT_THAT(MotionFrameNumbers({"left", "right", "000002", "000001"}),
              ElementsAre(0, 2, 4, 6));
}

TEST(FrameLogKeypoints, MillimetresToOneMicrometreAndBack) {
  Points3d keypoints(2, 3);
  keypoints << 0.1234567, -0.5, 0.0, 1.0, 2.0000004, -0.0000006;
  const std::vector<double> mm = KeypointsToMillimetres(keypoints);
  EXPECT_THAT(mm, ElementsAre(123.457, -500, 0, 1000, 2000, -0.001));
  EXPECT_THAT(KeypointsFromMillimetres(mm), testing::MatrixNear(keypoints, 5e-7));
}

}  // namespace
}  // namespace handlabel
