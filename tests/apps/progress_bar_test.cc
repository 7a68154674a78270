#include "apps/progress_bar.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace handlabel {
namespace {

std::string Contents(std::FILE* f) {
  std::rewind(f);
  std::string out;
  char buf[256];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) out.append(buf, n);
  return out;
}

TEST(ProgressBar, PlainLinesForLogs) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressBar bar(10, "frames", f, /*is_tty=*/0, /*plain_interval_s=*/0.0);
    bar.Update(3);
    bar.Update(10);
    bar.Finish();
  }
  const std::string out = Contents(f);
  std::fclose(f);
  EXPECT_NE(out.find("3/10 frames"), std::string::npos) << out;
  EXPECT_NE(out.find("frames/s"), std::string::npos) << out;
  EXPECT_NE(out.find("10/10 frames"), std::string::npos) << out;
  EXPECT_EQ(out.find('\r'), std::string::npos) << "no terminal control in logs";
  EXPECT_EQ(out.back(), '\n');
}

TEST(ProgressBar, RedrawsOneLineOnATerminal) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressBar bar(4, "frames", f, /*is_tty=*/1);
    bar.Update(1);
    bar.Finish();
  }
  const std::string out = Contents(f);
  std::fclose(f);
  EXPECT_NE(out.find("\r["), std::string::npos) << out;
  EXPECT_NE(out.find("1/4 frames"), std::string::npos) << out;
  EXPECT_NE(out.find("ETA"), std::string::npos) << out;
}

}  // namespace
}  // namespace handlabel
