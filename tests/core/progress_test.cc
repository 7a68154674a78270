#include "core/progress.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>

namespace handlabel {
namespace {

using ::testing::HasSubstr;

TEST(Progress, PlainModePrintsAboutTwentyLinesAndTheLastOne) {
  std::ostringstream out;
  {
    Progress progress(100, out, false);
    for (int i = 0; i < 100; ++i) progress.FrameDone(i == 7);
  }
  const std::string text = out.str();
  const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  EXPECT_GE(lines, 20);
  EXPECT_LE(lines, 22);
  EXPECT_EQ(text.find('\r'), std::string::npos);  // no bar in logs
  EXPECT_THAT(text, HasSubstr("100/100 frames"));
  EXPECT_THAT(text, HasSubstr("frames/s"));
  EXPECT_THAT(text, HasSubstr("1 failed"));
}

TEST(Progress, InteractiveModeRedrawsOneLineWithBarAndEndsWithANewline) {
  std::ostringstream out;
  {
    Progress progress(3, out, true);
    for (int i = 0; i < 3; ++i) progress.FrameDone(false);
  }
  const std::string text = out.str();
  EXPECT_THAT(text, HasSubstr("\r"));
  EXPECT_THAT(text, HasSubstr("[########################] 3/3 frames"));
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);
  EXPECT_EQ(text.back(), '\n');
}

TEST(Progress, RunningCountsGiveTheSameLinesAsSingleFrames) {
  std::ostringstream counted;
  {
    Progress progress(10, counted, false, "synth");
    progress.Update(4);
    progress.Update(3);  // late reports from other threads never go backwards
    progress.Update(10);
  }
  EXPECT_THAT(counted.str(), HasSubstr("synth 4/10 frames"));
  EXPECT_THAT(counted.str(), HasSubstr("synth 10/10 frames"));
  EXPECT_EQ(counted.str().find("3/10"), std::string::npos);
}

TEST(Progress, DurationsReadNaturally) {
  EXPECT_EQ(Progress::FormatDuration(12.4), "12s");
  EXPECT_EQ(Progress::FormatDuration(187), "3m07s");
  EXPECT_EQ(Progress::FormatDuration(3720), "1h02m");
}

}  // namespace
}  // namespace handlabel
