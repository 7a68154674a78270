// Bad inputs end to end (docs/reliability.md): each gives a non-zero exit or a failed
// frame whose reason names the file, field and expectation; nothing already written is
// lost.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "pipeline/label_outputs.h"
#include "pipeline/label_record.h"
#include "tests/apps/label_test_capture.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::RunHandlabelCommand;

using testing::EditJson;
using testing::ManifestEntry;

// Detections with every confidence 0 (a detector that saw nothing), a confidence of
// 7.5, and a broken image in a fit-only job with overlays: those frames fail by name,
// the others are labelled, and a rerun with --resume keeps the labels already written.
TEST(BadInputsCommand, FramesWithoutEvidenceOrWithBrokenFilesFailByName) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 4, 9);
  EditJson(dir + "/capture/detections/000000.json", [](nlohmann::json& j) {
    for (auto& v : j["views"]) v["confidence"] = std::vector<double>(21, 0.0);
  });
  EditJson(dir + "/capture/detections/000001.json",
           [](nlohmann::json& j) { j["views"][2]["confidence"][4] = 7.5; });
  std::string broken;
  for (const auto& e : fs::recursive_directory_iterator(dir + "/capture/images")) {
    if (e.path().string().find("000002") != std::string::npos) broken = e.path().string();
  }
  ASSERT_FALSE(broken.empty());
  std::ofstream(broken, std::ios::trunc) << "not a picture";
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  std::string text = testing::ReadFileBytes(job);  // a fit-only job with overlays
  text.replace(text.find("overlays: false"), 15, "overlays: true");
  std::ofstream(job, std::ios::trunc) << text;
  const auto r = RunHandlabelCommand({"label", "--job", job});
  EXPECT_EQ(r.status, 0) << r.err;  // the job goes on; failures are per frame
  EXPECT_THAT(r.out + r.err, HasSubstr("3 failed"));  // the summary: stderr
  const std::string out = dir + "/out";
  const nlohmann::json silent = ManifestEntry(out, "000000");
  EXPECT_EQ(silent["status"], "failed");
  EXPECT_THAT(silent["reason"].get<std::string>(), HasSubstr("detections/000000.json"));
  EXPECT_THAT(silent["reason"].get<std::string>(), HasSubstr("confidence"));
  const nlohmann::json high = ManifestEntry(out, "000001");
  EXPECT_EQ(high["status"], "failed");
  EXPECT_THAT(high["reason"].get<std::string>(), HasSubstr("views[2].confidence[4]"));
  EXPECT_THAT(high["reason"].get<std::string>(), HasSubstr("[0, 1]"));
  const nlohmann::json image = ManifestEntry(out, "000002");
  EXPECT_EQ(image["status"], "failed");
  EXPECT_THAT(image["reason"].get<std::string>(), HasSubstr(broken));
  EXPECT_FALSE(fs::exists(LabelFilePath(out, "000000")));
  const std::string kept = testing::ReadFileBytes(LabelFilePath(out, "000003"));
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(RunHandlabelCommand({"label", "--job", job, "--resume"}).status, 0);
  EXPECT_EQ(testing::ReadFileBytes(LabelFilePath(out, "000003")), kept);
}

// Detections damaged on the way (issue 46): a keypoint at 1e308 (was labelled 165-229 mm
// off with "0 failed") and a file whose `frame` names another frame (was used as this
// frame's 2D). Each fails its frame naming the file, the field and the range; the
// frames with good files are labelled.
TEST(BadInputsCommand, DetectionsOutOfRangeOrOfAnotherFrameFailTheirFrameByName) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 4, 9);
  const std::string det = dir + "/capture/detections/";
  EditJson(det + "000000.json", [](nlohmann::json& j) {
    j["views"][1]["keypoints"][5] = {1e308, 40.0};
  });
  fs::copy_file(det + "000002.json", det + "000001.json",
                fs::copy_options::overwrite_existing);
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  const auto r = RunHandlabelCommand({"label", "--job", job});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out + r.err, HasSubstr("2 failed"));
  const std::string out = dir + "/out";
  const std::string huge = ManifestEntry(out, "000000")["reason"];
  EXPECT_THAT(huge, HasSubstr("detections/000000.json"));
  EXPECT_THAT(huge, HasSubstr("views[1].keypoints[5]"));
  EXPECT_THAT(huge, HasSubstr("x in [-160, 320], y in [-120, 240]"));
  EXPECT_THAT(huge, HasSubstr("1e+308"));
  const std::string other = ManifestEntry(out, "000001")["reason"];
  EXPECT_THAT(other, HasSubstr("detections/000001.json: field 'frame'"));
  EXPECT_THAT(other, HasSubstr("'000001'"));
  EXPECT_THAT(other, HasSubstr("\"000002\""));
  for (const char* id : {"000002", "000003"}) {
    EXPECT_EQ(ManifestEntry(out, id)["status"], "ok") << id;
  }
}

// A job whose 2D comes from elsewhere (an evidence.detections folder here; a detector
// job alike) does not read the capture's own detections: a damaged one there no longer
// fails its frame (issue 46: a detector job failed frames on detections/*.json it did
// not use).
TEST(BadInputsCommand, AJobWithOther2dDoesNotReadTheCapturesOwnDetections) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 2, 9);
  fs::copy(dir + "/capture/detections", dir + "/det");
  EditJson(dir + "/capture/detections/000000.json",
           [](nlohmann::json& j) { j["views"][2]["confidence"][4] = 7.5; });
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  std::string text = testing::ReadFileBytes(job);
  text.replace(text.find("masks: none}"), 12,
               "masks: none, detections: " + dir + "/det}");
  std::ofstream(job, std::ios::trunc) << text;
  const auto r = RunHandlabelCommand({"label", "--job", job});
  EXPECT_EQ(r.status, 0) << r.err;
  for (const char* id : {"000000", "000001"}) {
    EXPECT_EQ(ManifestEntry(dir + "/out", id)["status"], "ok")
        << id << ": " << ManifestEntry(dir + "/out", id).dump();
  }
}

// A label cut short after it was logged: merge reports the frame (exit 1) and
// --resume labels it again; merge with another job's file leaves the manifest alone.
TEST(BadInputsCommand, MergeReportsDamagedLabelsAndRefusesAnotherJob) {
  const std::string dir = testing::ScratchDir();
  testing::WriteTestCapture(dir + "/capture", 3, 10);
  const std::string job = testing::WriteTestJob(dir, "job", "capture", "out");
  ASSERT_EQ(RunHandlabelCommand({"label", "--job", job}).status, 0);
  const std::string out = dir + "/out";
  const std::string label = LabelFilePath(out, "000001");
  const std::string full = testing::ReadFileBytes(label);
  fs::resize_file(label, full.size() / 3);
  auto r = RunHandlabelCommand({"merge", "--job", job});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.out, HasSubstr("000001 (label file"));
  EXPECT_THAT(r.out, HasSubstr("truncated"));
  EXPECT_EQ(RunHandlabelCommand({"label", "--job", job, "--resume"}).status, 0);
  EXPECT_EQ(testing::ReadFileBytes(label), full);
  EXPECT_EQ(RunHandlabelCommand({"merge", "--job", job}).status, 0);

  const std::string manifest = testing::ReadFileBytes(ManifestPath(out));
  std::string other = testing::ReadFileBytes(job);
  other.replace(other.find("seed: 3"), 7, "seed: 4");
  std::ofstream(dir + "/other.yaml") << other;
  r = RunHandlabelCommand({"merge", "--job", dir + "/other.yaml"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("job.json"));
  EXPECT_THAT(r.err, HasSubstr("another job"));
  EXPECT_EQ(testing::ReadFileBytes(ManifestPath(out)), manifest);
}

TEST(BadInputsCommand, EmptyModelFileIsNamedAsSuch) {
  const std::string path = testing::ScratchDir() + "/empty.npz";
  std::ofstream{path};
  const auto r = RunHandlabelCommand({"model", "info", path});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr(path));
  EXPECT_THAT(r.err, HasSubstr("an empty file"));
}

}  // namespace
}  // namespace handlabel
