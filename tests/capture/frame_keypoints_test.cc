// The checks a reader makes of one frame's keypoint or detection file
// (FrameKeypointsFromJson, capture/capture_format.h), through the reader of an
// `evidence.detections` folder (ReadDetectionsFile). The native capture's reader takes
// the same path: BadInputsCommand.DetectionsOutOfRangeOrOfAnotherFrameFailTheirFrameByName.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <limits>

#include "capture/capture_format.h"
#include "capture/detections_frame_source.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

Rig TwoCameras() {
  Rig rig;
  for (const char* name : {"left", "right"}) {
    rig.Add({name, Camera::Pinhole(100, 100, 80, 60, 160, 120), Rigid3()});
  }
  return rig;
}

// A detections file of frame `frame` with one view of camera "right" whose keypoint 3
// is at `keypoint`; the others at (50, 40).
std::string WriteDetections(const std::string& frame, const nlohmann::json& keypoint) {
  std::vector<ViewKeypoints> views(1);
  views[0].camera = "right";
  views[0].keypoints.uv_px.setConstant(50);
  views[0].keypoints.uv_px.col(1).setConstant(40);
  views[0].keypoints.confidence.setConstant(0.9);
  nlohmann::json j = ViewKeypointsToJson(frame, views, /*ground_truth=*/false);
  j["views"][0]["keypoints"][3] = keypoint;
  std::string name = frame;
  std::replace(name.begin(), name.end(), '/', '_');
  const std::string path = testing::ScratchDir() + "/" + name + ".json";
  std::ofstream(path) << j.dump();
  return path;
}

std::string ErrorOf(const std::string& path, const std::string& frame) {
  try {
    ReadDetectionsFile(path, frame, TwoCameras());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FrameKeypoints, PositionsNearTheImageAndNullAreRead) {
  for (const nlohmann::json& kp :
       {nlohmann::json{-160.0, 240.0}, nlohmann::json{320.0, -120.0},
        nlohmann::json{nullptr, nullptr}}) {
    const auto views = ReadDetectionsFile(WriteDetections("000002", kp), "000002",
                                          TwoCameras());
    ASSERT_EQ(views.size(), 2u);
    EXPECT_FALSE(views[0]);  // no view of "left"
    ASSERT_TRUE(views[1]);
    EXPECT_EQ(views[1]->uv_px(0, 0), 50);
  }
}

TEST(FrameKeypoints, AbsurdPositionsAreRefusedNamingTheKeypointAndTheRange) {
  for (const nlohmann::json& kp :
       {nlohmann::json{1e308, 40.0}, nlohmann::json{50.0, -1e308},
        nlohmann::json{321.0, 40.0}, nlohmann::json{50.0, nullptr}}) {
    const std::string path = WriteDetections("000002", kp);
    const std::string error = ErrorOf(path, "000002");
    EXPECT_THAT(error, HasSubstr(path)) << kp;
    EXPECT_THAT(error, HasSubstr("views[0].keypoints[3]")) << kp;
    EXPECT_THAT(error, HasSubstr("image of camera right (x in [-160, 320], y in "
                                 "[-120, 240]) or [null, null]"))
        << kp;
  }
}

TEST(FrameKeypoints, AFileOfAnotherFrameIsRefused) {
  const std::string path = WriteDetections("000003", {50.0, 40.0});
  const std::string error = ErrorOf(path, "000002");
  EXPECT_THAT(error, HasSubstr(path + ": field 'frame': expected '000002'"));
  EXPECT_THAT(error, HasSubstr("got \"000003\""));
  EXPECT_EQ(ErrorOf(path, "000003"), "");
  // Dataset frame ids are relative to the job's input folder: "ABF1/0000" is "0000"
  // read from the sequence's folder, not "ABF2/0000".
  const std::string sequence = WriteDetections("ABF1/0000", {50.0, 40.0});
  EXPECT_EQ(ErrorOf(sequence, "0000"), "");
  EXPECT_EQ(ErrorOf(sequence, "ABF1/0000"), "");
  EXPECT_THAT(ErrorOf(sequence, "ABF2/0000"), HasSubstr("field 'frame'"));
  EXPECT_THAT(ErrorOf(sequence, "10000"), HasSubstr("field 'frame'"));
}

}  // namespace
}  // namespace handlabel
