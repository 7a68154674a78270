#include "image/draw.h"

#include <gtest/gtest.h>

#include <string>

namespace handlabel {
namespace {

const Rgb kInk = {10, 20, 30};

// The image as text, one line per row: '#' where a pixel has kInk, '.' where it is
// untouched (0), '?' for anything else.
std::string Art(const ImageU8& image) {
  std::string out;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Rgb p = {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)};
      out += p == kInk ? '#' : p == Rgb{0, 0, 0} ? '.' : '?';
    }
    out += '\n';
  }
  return out;
}

TEST(Draw, SetPixelPaintsInsideAndClipsOutside) {
  ImageU8 image(3, 2, 3);
  SetPixel(&image, 1, 1, kInk);
  SetPixel(&image, -1, 0, kInk);
  SetPixel(&image, 3, 0, kInk);
  SetPixel(&image, 0, 2, kInk);
  EXPECT_EQ(Art(image), "...\n.#.\n");
}

TEST(Draw, LinesRoundEachSampleToTheNearestPixel) {
  ImageU8 image(4, 3, 3);
  // ceil(max(2, 1)) = 2 steps: (0, 0), (1, 0.5) -> (1, 1), (2, 1).
  DrawLine(&image, {0, 0}, {2, 1}, kInk);
  EXPECT_EQ(Art(image), "#...\n.##.\n....\n");
  // Three steps sample (0.67, 0.33) -> (1, 0) as well.
  ImageU8 denser(4, 3, 3);
  DrawLineSamples(&denser, {0, 0}, {2, 1}, 3, kInk);
  EXPECT_EQ(Art(denser), "##..\n.##.\n....\n");
  // Zero steps: the start alone.
  ImageU8 point(4, 3, 3);
  DrawLineSamples(&point, {2.4, 1.6}, {3, 0}, 0, kInk);
  EXPECT_EQ(Art(point), "....\n....\n..#.\n");
}

TEST(Draw, ThickLinesPaintASquarePenAtEverySample) {
  ImageU8 image(5, 3, 3);
  DrawLine(&image, {0, 0}, {2, 0}, kInk, 2);
  EXPECT_EQ(Art(image), "####.\n####.\n.....\n");
}

TEST(Draw, DiscsAndRings) {
  ImageU8 disc(5, 5, 3);
  DrawDisc(&disc, {2.2, 1.9}, 1.5, kInk);  // centre pixel (2, 2); d^2 <= 2.25
  EXPECT_EQ(Art(disc), ".....\n.###.\n.###.\n.###.\n.....\n");
  ImageU8 ring(5, 5, 3);
  DrawRing(&ring, {2, 2}, 2, kInk);  // 1 <= d^2 <= 4
  EXPECT_EQ(Art(ring), "..#..\n.###.\n##.##\n.###.\n..#..\n");
  ImageU8 clipped(3, 3, 3);
  DrawDisc(&clipped, {0, 0}, 1, kInk);
  EXPECT_EQ(Art(clipped), "##.\n#..\n...\n");
}

TEST(Draw, RoundLinesStampDiscsAndSkipLinesFarOutside) {
  ImageU8 image(6, 3, 3);
  DrawThickLine(&image, {1, 1}, {4, 1}, 2, kInk);  // discs of radius 1 at x = 1..4
  EXPECT_EQ(Art(image), ".####.\n######\n.####.\n");
  ImageU8 far(6, 3, 3);
  DrawThickLine(&far, {1, 1}, {1e6, 1}, 2, kInk);
  EXPECT_EQ(Art(far), "......\n......\n......\n");
}

TEST(Draw, TextUsesTheFiveBySevenFont) {
  ImageU8 image(12, 7, 3);
  DrawText(&image, 0, 0, "1a", kInk);  // lower case drawn as upper case
  EXPECT_EQ(Art(image),
            "..#....###..\n"
            ".##...#...#.\n"
            "..#...#...#.\n"
            "..#...#...#.\n"
            "..#...#####.\n"
            "..#...#...#.\n"
            ".###..#...#.\n");
  // Scale 2, clipped: '-' is font row 3, so image rows -4 + 6 and -4 + 7.
  ImageU8 big(6, 4, 3);
  DrawText(&big, 0, -4, "-", kInk, 2);
  EXPECT_EQ(Art(big), "......\n......\n######\n######\n");
}

}  // namespace
}  // namespace handlabel
