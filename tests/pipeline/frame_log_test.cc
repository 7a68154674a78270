#include "pipeline/frame_log.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// A record with the fields these tests set; the rest keep their defaults.
FrameRecord Rec(const std::string& frame, const std::string& status,
                const std::string& path, const std::string& reason, double seconds,
                std::map<std::string, double> metrics = {}) {
  FrameRecord r;
  r.frame = frame;
  r.status = status;
  r.path = path;
  r.reason = reason;
  r.seconds = seconds;
  r.metrics = std::move(metrics);
  return r;
}

namespace fs = std::filesystem;

std::string TempDir() { return testing::ScratchDir(); }

TEST(FrameLog, RecordsSurviveReopenAndLaterRecordsSupersede) {
  const std::string path = TempDir() + "/shard-0-of-1.jsonl";
  {
    FrameLog log(path);
    log.Record(Rec("000001", "failed", "", "no views", 0.1));
    log.Record(Rec("000002", "ok", "network", "", 0.2));
    log.Record(Rec("000001", "ok", "fit", "", 0.3));
  }
  FrameLog reopened(path);
  EXPECT_TRUE(reopened.IsDone("000001"));
  EXPECT_TRUE(reopened.IsDone("000002"));
  EXPECT_FALSE(reopened.IsDone("000003"));
  const auto latest = reopened.Latest();
  ASSERT_EQ(latest.size(), 2u);
  EXPECT_EQ(latest[0].path, "fit");
}

// Which of several detected hands a frame was labelled from (FrameInput::evidence_hand):
// kept through a reopen; records of one hand have no "hand".
TEST(FrameLog, TheEvidenceHandRoundTrips) {
  const std::string path = TempDir() + "/shard-0-of-1.jsonl";
  FrameRecord two = Rec("000001", "ok", "fit", "", 0.5);
  two.hand = "hand 2 of 2 (left)";
  {
    FrameLog log(path);
    log.Record(two);
    log.Record(Rec("000002", "ok", "fit", "", 0.2));
  }
  const auto latest = FrameLog::Read(path);
  ASSERT_EQ(latest.size(), 2u);
  EXPECT_EQ(latest[0].hand, "hand 2 of 2 (left)");
  EXPECT_EQ(latest[1].hand, "");
  std::ifstream in(path);
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  EXPECT_NE(first.find("\"hand\":\"hand 2 of 2 (left)\""), std::string::npos) << first;
  EXPECT_EQ(second.find("\"hand\""), std::string::npos) << second;
}

TEST(FrameLog, StageTimesRoundTripAndOlderRecordsHaveNone) {
  const std::string path = TempDir() + "/shard-0-of-1.jsonl";
  FrameRecord timed = Rec("000001", "ok", "fit", "", 0.5);
  timed.stages = {{"read", 0.125}, {"detect.palm", 0.25}, {"fit.keypoints", 0.125}};
  {
    FrameLog log(path);
    log.Record(timed);
    log.Record(Rec("000002", "ok", "fit", "", 0.2));  // as a log before stage times
  }
  const std::vector<FrameRecord> read = FrameLog::Read(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].stages, timed.stages);
  EXPECT_TRUE(read[1].stages.empty());
  // An older record's line has no "stages" field at all.
  std::ifstream in(path);
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  EXPECT_NE(first.find("\"stages\""), std::string::npos);
  EXPECT_EQ(second.find("\"stages\""), std::string::npos);
}

TEST(FrameLog, PartialLastLineFromACrashIsIgnored) {
  const std::string path = TempDir() + "/log.jsonl";
  {
    FrameLog log(path);
    log.Record(Rec("a", "ok", "network", "", 0));
  }
  std::ofstream(path, std::ios::app) << "{\"frame\": \"b\", \"sta";  // killed mid-write
  FrameLog log(path);
  EXPECT_TRUE(log.IsDone("a"));
  EXPECT_FALSE(log.IsDone("b"));
}

TEST(FrameLog, AppendAfterAPartialLineStartsAFreshLine) {
  const std::string path = TempDir() + "/log.jsonl";
  {
    FrameLog log(path);
    log.Record(Rec("a", "ok", "network", "", 0));
  }
  std::ofstream(path, std::ios::app) << "{\"frame\": \"b\", \"sta";  // killed mid-write
  {
    FrameLog log(path);
    log.Record(Rec("b", "ok", "fit", "", 0, {{"labels/mpjpe_mm", 2.5}}));
  }
  const auto records = FrameLog::Read(path);  // would throw on a glued line
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].frame, "b");
  EXPECT_EQ(records[1].metrics.at("labels/mpjpe_mm"), 2.5);
}

TEST(FrameLog, MalformedCompleteLineNamesFileAndLine) {
  const std::string path = TempDir() + "/log.jsonl";
  std::ofstream(path) << "{\"frame\":\"a\",\"status\":\"ok\"}\n{\"frame\":\"b\"}\n";
  try {
    FrameLog log(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("log.jsonl:2"), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, ReplacesContentAndLeavesNoTemporary) {
  const std::string dir = TempDir();
  const std::string path = dir + "/sub/label.json";
  WriteFileAtomically(path, "first");
  WriteFileAtomically(path, "second");
  EXPECT_EQ(testing::ReadFileBytes(path), "second");
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  std::ofstream(dir + "/sub/x.json.tmp.123") << "half";
  EXPECT_EQ(RemoveStaleTemporaries(dir), 1);
  EXPECT_EQ(testing::ReadFileBytes(path), "second");
}

}  // namespace
}  // namespace handlabel
