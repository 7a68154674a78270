#include "pipeline/contact_sheet.h"

#include <gtest/gtest.h>

#include "pipeline/capsule_hand.h"
#include "pipeline/synth_capture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

TEST(ContactSheet, TilesEveryViewAndDrawsKeypointsWhereTheyAre) {
  const std::string dir = testing::ScratchDir() + "/cap";
  SynthCaptureOptions o;
  o.rig.preset = "random";
  o.rig.num_cameras = 3;
  o.rig.width = 120;
  o.rig.height = 90;
  o.num_frames = 1;
  o.num_threads = 1;
  o.view.background.clutter = false;  // grey, so drawn colours stand out
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, dir, "builtin:capsule");
  const CaptureReader capture(dir);
  ContactSheetOptions so;
  so.columns = 2;
  so.tile_width = 120;  // 1:1 scale
  const ImageU8 sheet = MakeContactSheet(capture, 0, so);
  EXPECT_EQ(sheet.width, 2 * 120 + 3 * 4);
  EXPECT_EQ(sheet.height, 2 * 90 + 3 * 4);
  // The wrist dot (red, filled when visible) of camera 0 sits at its keypoint.
  const ViewKeypoints kp = capture.ReadKeypoints(0)[0];
  ASSERT_EQ(kp.visibility[0], 2);
  const int x = 4 + static_cast<int>(std::lround(kp.keypoints(0, 0)));
  const int y = 4 + static_cast<int>(std::lround(kp.keypoints(0, 1)));
  EXPECT_EQ(sheet.at(x, y, 0), 255);
  EXPECT_EQ(sheet.at(x, y, 1), 60);
  // Crops are square tiles.
  so.crop_to_hand = true;
  const ImageU8 crops = MakeContactSheet(capture, 0, so);
  EXPECT_EQ(crops.height, 2 * 120 + 3 * 4);
}

}  // namespace
}  // namespace handlabel
