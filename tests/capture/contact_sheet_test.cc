#include "capture/contact_sheet.h"

#include <gtest/gtest.h>

#include "capture/synth_capture.h"
#include "hand/capsule_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// One frame of the capsule hand seen by `cameras` random 120 x 90 cameras on a plain
// grey background, so drawn colours stand out; returns the capture folder.
std::string WriteGreyCapture(int cameras) {
  const std::string dir = testing::ScratchDir() + "/cap";
  SynthCaptureOptions o;
  o.rig.preset = "random";
  o.rig.num_cameras = cameras;
  o.rig.width = 120;
  o.rig.height = 90;
  o.num_frames = 1;
  o.num_threads = 1;
  o.view.background.clutter = false;
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, dir, "builtin:capsule");
  return dir;
}

TEST(ContactSheet, TilesEveryViewAndDrawsKeypointsWhereTheyAre) {
  const CaptureReader capture(WriteGreyCapture(3));
  ContactSheetOptions so;
  so.columns = 2;
  so.tile_width = 120;  // 1:1 scale
  const ImageU8 sheet = MakeContactSheet(capture, 0, so);
  EXPECT_EQ(sheet.width, 2 * 120 + 3 * 4);
  EXPECT_EQ(sheet.height, 2 * 90 + 3 * 4);
  // The wrist dot (red, filled when visible) of camera 0 sits at its keypoint.
  const ViewKeypoints kp = capture.ReadKeypoints(0)[0];
  ASSERT_EQ(kp.visibility[0], 2);
  const int x = 4 + static_cast<int>(std::lround(kp.keypoints.uv_px(0, 0)));
  const int y = 4 + static_cast<int>(std::lround(kp.keypoints.uv_px(0, 1)));
  EXPECT_EQ(sheet.at(x, y, 0), 255);
  EXPECT_EQ(sheet.at(x, y, 1), 60);
  // Crops are square tiles.
  so.crop_to_hand = true;
  const ImageU8 crops = MakeContactSheet(capture, 0, so);
  EXPECT_EQ(crops.height, 2 * 120 + 3 * 4);
}

// At 1:1 scale with keypoints off, camera 0's tile is its image with exactly the mask's
// border pixels (on, with a 4-neighbour off) painted in the outline colour.
TEST(ContactSheet, OutlinesExactlyTheMaskBorder) {
  const CaptureReader capture(WriteGreyCapture(2));
  ContactSheetOptions so;
  so.columns = 2;
  so.tile_width = 120;
  so.keypoints = false;
  const ImageU8 sheet = MakeContactSheet(capture, 0, so);
  const ImageU8 image = capture.ReadImage(0, 0), mask = capture.ReadMask(0, 0);
  auto on = [&](int x, int y) { return mask.at(x, y, 0) != 0; };
  int border = 0, inside = 0;
  for (int y = 1; y + 1 < 90; ++y) {
    for (int x = 1; x + 1 < 120; ++x) {
      const bool is_border =
          on(x, y) && !(on(x - 1, y) && on(x + 1, y) && on(x, y - 1) && on(x, y + 1));
      border += is_border;
      inside += on(x, y) && !is_border;
      for (int k = 0; k < 3; ++k) {
        const int want = is_border ? (k == 0 ? 0 : k == 1 ? 255 : 80) : image.at(x, y, k);
        ASSERT_EQ(sheet.at(4 + x, 4 + y, k), want) << x << "," << y << " channel " << k;
      }
    }
  }
  EXPECT_GT(border, 20);  // the hand is in view: the check above saw an outline
  EXPECT_GT(inside, 20);
}

}  // namespace
}  // namespace handlabel
