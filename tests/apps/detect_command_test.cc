#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/capture_reader.h"
#include "core/data_dir.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::RunHandlabelCommand;

bool ModelsPresent() {
  return std::filesystem::exists(
             ShippedModelPath("mediapipe/palm_detection_full.tflite")) &&
         std::filesystem::exists(ShippedModelPath("mediapipe/hand_landmark_full.tflite"));
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(DetectCommand, UsageErrors) {
  EXPECT_EQ(RunHandlabelCommand({"detect"}).status, 2);
  EXPECT_EQ(RunHandlabelCommand({"detect", "--images", "a.png"}).status, 2);  // no --out
  EXPECT_EQ(
      RunHandlabelCommand({"detect", "--capture", "c", "--images", "a.png", "--out", "o"})
          .status,
      2);
  const testing::CommandResult bad = RunHandlabelCommand(
      {"detect", "--images", "a.png", "--out", testing::ScratchDir(), "--model", "huge"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("full or lite"), std::string::npos) << bad.err;
}

TEST(DetectCommand, KeepsExistingDetectionsUnlessOverwriteIsGiven) {
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "random", "--cameras", "2",
                                 "--size", "64x48", "--frames", "1", "--hand-model",
                                 "capsule", "--out", dir + "/cap"})
                .status,
            0);
  const std::string before = ReadJson(dir + "/cap/detections/000000.json").dump();
  const testing::CommandResult r =
      RunHandlabelCommand({"detect", "--capture", dir + "/cap"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("files.detections"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(ReadJson(dir + "/cap/detections/000000.json").dump(), before);
}

// The multi-view detector on a rendered DexYCB-like frame (seed 7: MediaPipe's palm
// detector fires in 2 of its 8 views): the views agree on the hand, the others are found
// from it, detections lie near the true keypoints, views without one say why.
TEST(DetectCommand, CaptureViewsGetDetectionsOrReasons) {
  if (!ModelsPresent()) {
    GTEST_SKIP() << "MediaPipe models absent: run scripts/fetch-mediapipe-models";
  }
  const std::string dir = testing::ScratchDir();
  ASSERT_EQ(RunHandlabelCommand({"synth", "--preset", "dexycb", "--frames", "1", "--seed",
                                 "3", "--out", dir + "/cap"})
                .status,
            0);
  const testing::CommandResult r =
      RunHandlabelCommand({"detect", "--capture", dir + "/cap", "--overwrite"});
  ASSERT_EQ(r.status, 0) << r.err;
  const CaptureReader capture(dir + "/cap");
  const auto truth = capture.ReadKeypoints(0);
  const nlohmann::json det = ReadJson(dir + "/cap/detections/000000.json");
  ASSERT_EQ(det["views"].size(), static_cast<size_t>(capture.num_cameras()));
  const auto views = capture.ReadDetections(0);  // the native reader accepts the file
  EXPECT_TRUE(det["hand"]["found"].get<bool>());
  EXPECT_EQ(det["hand"]["side"], "right");  // synth renders right hands
  int detected = 0;
  for (int c = 0; c < capture.num_cameras(); ++c) {
    detected += det["views"][c]["detected"].get<bool>() ? 1 : 0;
  }
  EXPECT_GE(detected, 6);
  for (int c = 0; c < capture.num_cameras(); ++c) {
    const nlohmann::json& v = det["views"][c];
    if (!v["detected"].get<bool>()) {
      EXPECT_FALSE(v["reason"].get<std::string>().empty());
      continue;
    }
    // Median distance to the true keypoints visible in the view.
    std::vector<double> errors;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (views[c].keypoints.confidence(k) <= 0 || truth[c].visibility[k] != 2) continue;
      errors.push_back(
          (views[c].keypoints.uv_px.row(k) - truth[c].keypoints.uv_px.row(k)).norm());
    }
    if (errors.empty()) continue;
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    EXPECT_LT(errors[errors.size() / 2], 25.0) << "camera " << c;
  }
}

}  // namespace
}  // namespace handlabel
