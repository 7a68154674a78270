#include "image/median_image.h"

#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"

namespace handlabel {
namespace {

ImageU8 RandomImage(int w, int h, std::mt19937_64& rng) {
  ImageU8 im(w, h, 3);
  std::uniform_int_distribution<int> level(0, 255);
  for (uint8_t& v : im.data) v = static_cast<uint8_t>(level(rng));
  return im;
}

// A white square at (x0, y0) over `background`, and the mask of the square.
void WithSquare(const ImageU8& background, int x0, int y0, int side, ImageU8* image,
                ImageU8* mask) {
  *image = background;
  *mask = ImageU8(background.width, background.height, 1);
  for (int y = y0; y < y0 + side; ++y) {
    for (int x = x0; x < x0 + side; ++x) {
      for (int c = 0; c < 3; ++c) image->at(x, y, c) = 255;
      mask->at(x, y) = 255;
    }
  }
}

TEST(MedianImage, LeavingOutTheHandGivesTheEmptySceneWhereTheHandStays) {
  std::mt19937_64 rng(3);
  const ImageU8 empty_scene = RandomImage(40, 30, rng);
  // The "hand" stays at (5, 5) in 4 of 7 frames: a plain median keeps it there.
  const int xs[] = {5, 5, 5, 5, 20, 12, 25};
  std::vector<ImageU8> images(7), masks(7);
  for (int i = 0; i < 7; ++i) WithSquare(empty_scene, xs[i], 5, 8, &images[i], &masks[i]);

  const ImageU8 plain = MedianImage(images, {});
  EXPECT_EQ(plain.at(7, 7, 0), 255);
  const ImageU8 median = MedianImage(images, masks);
  EXPECT_EQ(median.data, empty_scene.data);
}

TEST(MedianImage, APixelEveryImageLeavesOutTakesTheMedianOfAll) {
  std::vector<ImageU8> images, masks;
  for (int v : {10, 200, 50}) {
    images.emplace_back(2, 1, 1, static_cast<uint8_t>(v));
    ImageU8 mask(2, 1, 1);
    mask.at(0, 0) = 1;  // every image leaves out pixel 0
    masks.push_back(mask);
  }
  masks[1].at(1, 0) = 1;  // pixel 1: the 10 and the 50 count
  const ImageU8 median = MedianImage(images, masks);
  EXPECT_EQ(median.at(0, 0), 50);  // of 10, 200, 50
  EXPECT_EQ(median.at(1, 0), 10);  // lower middle of 10, 50
}

TEST(MedianImage, InconsistentSizesAreNamed) {
  std::vector<ImageU8> images = {ImageU8(4, 4, 3), ImageU8(4, 4, 3), ImageU8(4, 5, 3)};
  try {
    MedianImage(images, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "images[2]");
    EXPECT_EQ(e.got(), "4 x 5 x 3");
  }
  images.pop_back();
  try {
    MedianImage(images, {ImageU8(4, 4, 1), ImageU8(4, 4, 3)});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "left_out[1]");
  }
  EXPECT_THROW(MedianImage({}, {}), InputError);
}

}  // namespace
}  // namespace handlabel
