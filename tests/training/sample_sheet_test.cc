#include "training/sample_sheet.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace handlabel {
namespace {

constexpr int kSide = 32;

// A view whose crop is a gradient and whose keypoints all sit in the crop's top-left
// quarter (so the skeleton is drawn there only).
TrainingView GradientView(float offset, float weight) {
  TrainingView view;
  view.image.resize(3 * kSide * kSide);
  for (int c = 0; c < 3; ++c) {
    for (int i = 0; i < kSide * kSide; ++i) {
      view.image[c * kSide * kSide + i] = offset + 0.5f * (i % kSide) / kSide - 0.25f;
    }
  }
  for (int k = 0; k < 21; ++k) {
    view.joints_2d.row(k) << 2 + (k % 5) * 2, 2 + (k / 5) * 2;
    view.joints_2d_weight[k] = 1;
  }
  view.view_weight = weight;
  return view;
}

TEST(TrainingSampleSheet, TilesShowTheCropsTheirSkeletonsAndUnlocatedViews) {
  TrainingSample a, b;
  a.views = {GradientView(0, 1), GradientView(0.1f, 1)};
  b.views = {GradientView(-0.1f, 0), GradientView(0, 1)};
  const ImageU8 sheet = MakeTrainingSampleSheet({a, b});
  ASSERT_EQ(sheet.width, 2 * kSide + 2);
  ASSERT_EQ(sheet.height, 2 * kSide + 2);
  // Away from the skeleton (bottom-right quarter of a tile, inside the frame) a tile
  // is its crop's pixels: RGB = (value + 0.5) * 255.
  for (int row = 0; row < 2; ++row) {
    for (int v = 0; v < 2; ++v) {
      const TrainingView& view = (row == 0 ? a : b).views[v];
      for (int y = kSide / 2; y < kSide - 3; ++y) {
        for (int x = kSide / 2; x < kSide - 3; ++x) {
          const float value = view.image[y * kSide + x];
          const int expected = static_cast<int>(std::lround((value + 0.5f) * 255.0f));
          EXPECT_EQ(sheet.at(v * (kSide + 2) + x, row * (kSide + 2) + y, 0), expected);
        }
      }
    }
  }
  // The skeleton is drawn where its keypoints are: some pixel in the top-left quarter
  // of the first tile differs from the crop.
  int skeleton = 0;
  for (int y = 0; y < kSide / 2; ++y) {
    for (int x = 0; x < kSide / 2; ++x) {
      const int crop =
          static_cast<int>(std::lround((a.views[0].image[y * kSide + x] + 0.5f) * 255));
      skeleton += sheet.at(x, y, 0) != crop || sheet.at(x, y, 1) != crop;
    }
  }
  EXPECT_GT(skeleton, 10);
  // The view of weight 0 (sample b, view 0) has a red frame; the others do not.
  const int y0 = kSide + 2;
  EXPECT_EQ(sheet.at(0, y0 + kSide / 2, 0), 255);
  EXPECT_EQ(sheet.at(0, y0 + kSide / 2, 1), 0);
  EXPECT_NE(sheet.at(kSide + 2, y0 + kSide / 2, 1), 0);
}

TEST(TrainingSampleSheet, SamplesOfOtherShapesAreNamed) {
  TrainingSample a, b;
  a.views = {GradientView(0, 1), GradientView(0, 1)};
  b.views = {GradientView(0, 1)};
  try {
    MakeTrainingSampleSheet({a, b});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "samples[1].views");
  }
  EXPECT_THROW(MakeTrainingSampleSheet({}), InputError);
}

}  // namespace
}  // namespace handlabel
