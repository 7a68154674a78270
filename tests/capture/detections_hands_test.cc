// A detections file of several hands (`detect --max-hands N`, docs/detector.md): the
// first hand where a single-hand file has it, the others in "other_hands"; a reader
// takes the hand of the capture's side (ChooseDetectionsHand), through the reader of an
// `evidence.detections` folder (ReadDetectionsFile).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "capture/capture_format.h"
#include "capture/detections_frame_source.h"
#include "capture/native_frame_source.h"
#include "capture/synth_capture.h"
#include "core/errors.h"
#include "core/json_util.h"
#include "hand/capsule_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

Rig OneCamera() {
  Rig rig;
  rig.Add({"cam", Camera::Pinhole(100, 100, 80, 60, 160, 120), Rigid3()});
  return rig;
}

// One hand's record: camera "cam" with every keypoint at (x, 40), and its hand record.
nlohmann::json HandRecord(double x, const std::string& side, bool found) {
  std::vector<ViewKeypoints> views(1);
  views[0].camera = "cam";
  views[0].keypoints.uv_px.col(0).setConstant(x);
  views[0].keypoints.uv_px.col(1).setConstant(40);
  views[0].keypoints.confidence.setConstant(0.9);
  nlohmann::json j = ViewKeypointsToJson("000001", views, /*ground_truth=*/false);
  j["hand"] = {{"found", found}, {"side", side}, {"side_score", 0.9}, {"palm_views", 2}};
  return j;
}

// A file whose first hand (x = 10) is `first_side`, then the hands `others` {x, side}.
nlohmann::json TwoHandFile(const std::string& first_side,
                           const std::vector<std::pair<double, std::string>>& others) {
  nlohmann::json file = HandRecord(10, first_side, true);
  file["detector"] = "mediapipe_hands";
  for (const auto& [x, side] : others) {
    nlohmann::json hand = HandRecord(x, side, true);
    hand.erase("frame");
    file["other_hands"].push_back(hand);
  }
  return file;
}

double FirstX(const DetectionsHandChoice& choice) {
  return choice.record["views"][0]["keypoints"][0][0].get<double>();
}

TEST(DetectionsHands, TheHandOfTheCapturesSideIsTaken) {
  const nlohmann::json file = TwoHandFile("right", {{60, "left"}, {90, "left"}});
  const DetectionsHandChoice left = ChooseDetectionsHand(file, HandSide::kLeft, "f");
  EXPECT_EQ(left.index, 1);  // the first left hand found
  EXPECT_EQ(left.count, 3);
  EXPECT_EQ(FirstX(left), 60);
  EXPECT_EQ(left.record["frame"], "000001");  // still checked against the frame
  EXPECT_EQ(left.Describe(), "hand 2 of 3 (left)");
  const DetectionsHandChoice right = ChooseDetectionsHand(file, HandSide::kRight, "f");
  EXPECT_EQ(right.index, 0);
  EXPECT_EQ(FirstX(right), 10);
  EXPECT_EQ(right.Describe(), "hand 1 of 3 (right)");
  // No side: the first hand, whatever was looked for (a contact sheet draws it).
  nlohmann::json looked_for_two = file;
  looked_for_two["max_hands"] = 2;
  EXPECT_EQ(ChooseDetectionsHand(looked_for_two, std::nullopt, "f").index, 0);
  EXPECT_EQ(FirstX(ChooseDetectionsHand(looked_for_two, std::nullopt, "f")), 10);
}

TEST(DetectionsHands, NoHandOfTheSideOrOneHandGivesTheFirst) {
  const nlohmann::json rights = TwoHandFile("right", {{60, "right"}});
  EXPECT_EQ(ChooseDetectionsHand(rights, HandSide::kLeft, "f").index, 0);
  // A hand that was not found (no 3D hand) is not taken for its side.
  nlohmann::json lost = TwoHandFile("right", {{60, "left"}});
  lost["other_hands"][0]["hand"]["found"] = false;
  EXPECT_EQ(ChooseDetectionsHand(lost, HandSide::kLeft, "f").index, 0);
  // A single-hand file is read as before, whatever its side, and says nothing.
  const nlohmann::json single = HandRecord(10, "right", true);
  const DetectionsHandChoice choice = ChooseDetectionsHand(single, HandSide::kLeft, "f");
  EXPECT_EQ(choice.index, 0);
  EXPECT_EQ(choice.record, single);
  EXPECT_EQ(choice.Describe(), "");
}

// Where several hands were looked for and none is of the capture's side, the frame has
// no hand of that side: the other hand is not taken in its place.
TEST(DetectionsHands, SeveralLookedForAndNoneOfTheSideFailsTheFrame) {
  nlohmann::json file = TwoHandFile("right", {{60, "right"}});
  file["max_hands"] = 2;
  const std::string error = testing::InputErrorOf(
      [&] { ChooseDetectionsHand(file, HandSide::kLeft, "det.json"); });
  EXPECT_THAT(error, HasSubstr("det.json"));
  EXPECT_THAT(error, HasSubstr("a found left hand (the capture's side)"));
  EXPECT_THAT(error, HasSubstr("2 hand(s), none left"));
  // One hand found of two looked for, of the side: taken, and said.
  nlohmann::json one = HandRecord(10, "left", true);
  one["max_hands"] = 2;
  EXPECT_EQ(ChooseDetectionsHand(one, HandSide::kLeft, "f").Describe(),
            "hand 1 of 1 (left)");
  one["max_hands"] = "two";
  EXPECT_THAT(
      testing::InputErrorOf([&] { ChooseDetectionsHand(one, HandSide::kLeft, "f"); }),
      HasSubstr("max_hands"));
}

TEST(DetectionsHands, ReadDetectionsFileTakesTheSidesHand) {
  const std::string path = testing::ScratchDir() + "/000001.json";
  std::ofstream(path) << TwoHandFile("right", {{60, "left"}}).dump();
  DetectionsHandChoice choice;
  const auto left =
      ReadDetectionsFile(path, "000001", OneCamera(), HandSide::kLeft, &choice);
  ASSERT_TRUE(left[0]);
  EXPECT_EQ(left[0]->uv_px(5, 0), 60);
  EXPECT_EQ(choice.index, 1);
  const auto right = ReadDetectionsFile(path, "000001", OneCamera(), HandSide::kRight);
  EXPECT_EQ(right[0]->uv_px(5, 0), 10);
  // An old reader's call (no side) reads the first hand.
  EXPECT_EQ(ReadDetectionsFile(path, "000001", OneCamera())[0]->uv_px(5, 0), 10);
}

TEST(DetectionsHands, MalformedOtherHandsAreRefusedByName) {
  nlohmann::json file = TwoHandFile("right", {});
  file["other_hands"] = "left";
  const std::string error = testing::InputErrorOf(
      [&] { ChooseDetectionsHand(file, HandSide::kLeft, "det.json"); });
  EXPECT_THAT(error, HasSubstr("det.json"));
  EXPECT_THAT(error, HasSubstr("other_hands"));
  nlohmann::json no_found = TwoHandFile("right", {{60, "left"}});
  no_found["other_hands"][0]["hand"].erase("found");
  EXPECT_THAT(testing::InputErrorOf(
                  [&] { ChooseDetectionsHand(no_found, HandSide::kLeft, "det.json"); }),
              HasSubstr("other_hands[0].hand.found"));
}

// A native capture of the left hand whose detections hold two hands, the right one first
// (it had more views): a label job's reader takes the left one and says so.
TEST(DetectionsHands, ANativeCaptureOfTheLeftHandReadsItsLeftHand) {
  const std::string dir = testing::ScratchDir() + "/cap";
  SynthCaptureOptions o;
  o.rig.preset = "random";
  o.rig.num_cameras = 2;
  o.rig.width = 120;
  o.rig.height = 90;
  o.num_frames = 1;
  o.num_threads = 1;
  WriteSynthCapture(MakeCapsuleHand(HandSide::kLeft), o, dir, "builtin:capsule");
  const std::string path = dir + "/detections/000000.json";
  nlohmann::json file = ReadJsonFileStrict(path);
  nlohmann::json left = file;  // the simulated views, moved 3 px to the right
  left.erase("frame");
  for (nlohmann::json& view : left["views"]) {
    for (nlohmann::json& kp : view["keypoints"]) {
      if (!kp[0].is_null()) kp[0] = kp[0].get<double>() + 3;
    }
  }
  left["hand"] = {{"found", true}, {"side", "left"}};
  file["hand"] = {{"found", true}, {"side", "right"}};
  file["other_hands"] = {left};
  file["max_hands"] = 2;
  std::ofstream(path) << file.dump();

  const NativeFrameSource source(dir, std::nullopt, "detections");
  ASSERT_EQ(source.side(), HandSide::kLeft);
  const FrameInput frame = source.Load("000000");
  EXPECT_EQ(frame.evidence_hand, "hand 2 of 2 (left)");
  const nlohmann::json& first_view = file["views"][0];
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (first_view["keypoints"][k][0].is_null()) continue;
    ASSERT_TRUE(frame.keypoints_2d[0]);
    EXPECT_DOUBLE_EQ(frame.keypoints_2d[0]->uv_px(k, 0),
                     first_view["keypoints"][k][0].get<double>() + 3);
  }
}

}  // namespace
}  // namespace handlabel
