#include "network/poem/mask_sheet.h"

#include <gtest/gtest.h>

#include "core/errors.h"

namespace handlabel {
namespace {

constexpr int kCrop = 16;  // crop pixels; the mask head's grid is kCrop / 4 = 4 cells

// A view whose image is the grey level `grey` everywhere and whose true mask is the
// square [4, 12) x [4, 12).
TrainingView SquareView(int grey) {
  TrainingView v;
  v.image.assign(3 * kCrop * kCrop, grey / 255.0f - 0.5f);
  v.mask.assign(kCrop * kCrop, 0.0f);
  for (int y = 4; y < 12; ++y)
    for (int x = 4; x < 12; ++x) v.mask[y * kCrop + x] = 1.0f;
  return v;
}

// Within one grey level: the network's float input does not hold grey / 255 exactly.
void ExpectPixel(const ImageU8& image, int x, int y, int r, int g, int b) {
  EXPECT_NEAR(image.at(x, y, 0), r, 1) << x << "," << y;
  EXPECT_NEAR(image.at(x, y, 1), g, 1) << x << "," << y;
  EXPECT_NEAR(image.at(x, y, 2), b, 1) << x << "," << y;
}

TEST(MaskSheet, TintsPredictedCellsAndOutlinesTheTrueMaskInEveryView) {
  TrainingSample sample;
  sample.views = {SquareView(100), SquareView(200)};
  PoemPrediction prediction;
  // View 0: the second row of cells (crop rows 4-7, the square's top half) predicted.
  prediction.masks.assign(2, std::vector<float>(16, 0.1f));
  for (int j = 0; j < 4; ++j) prediction.masks[0][1 * 4 + j] = 0.9f;
  const ImageU8 sheet = MakeMaskSheet({sample}, {prediction});
  ASSERT_EQ(sheet.width, 2 * kCrop + 2);  // two tiles and a 2-pixel gap
  ASSERT_EQ(sheet.height, kCrop);

  ExpectPixel(sheet, 4, 6, 0, 255, 0);      // the square's left edge: green outline
  ExpectPixel(sheet, 11, 10, 0, 255, 0);    // its right edge
  ExpectPixel(sheet, 6, 5, 178, 50, 50);    // inside, predicted: tinted red
  ExpectPixel(sheet, 1, 5, 178, 50, 50);    // outside the square, predicted
  ExpectPixel(sheet, 6, 9, 100, 100, 100);  // inside, not predicted: the image
  ExpectPixel(sheet, 1, 1, 100, 100, 100);  // outside, not predicted
  // View 1 in the second tile, with its own image and nothing predicted.
  const int x1 = kCrop + 2;
  ExpectPixel(sheet, x1 + 4, 6, 0, 255, 0);
  ExpectPixel(sheet, x1 + 6, 5, 200, 200, 200);
  ExpectPixel(sheet, kCrop, 5, 255, 255, 255);  // the gap stays white
}

TEST(MaskSheet, RefusesPredictionsWithoutMasks) {
  TrainingSample sample;
  sample.views = {SquareView(100)};
  EXPECT_THROW(MakeMaskSheet({sample}, {PoemPrediction{}}), InputError);
  TrainingSample no_masks = sample;
  no_masks.views[0].mask.clear();
  PoemPrediction prediction;
  prediction.masks.assign(1, std::vector<float>(16, 0.9f));
  EXPECT_THROW(MakeMaskSheet({no_masks}, {prediction}), InputError);
}

}  // namespace
}  // namespace handlabel
