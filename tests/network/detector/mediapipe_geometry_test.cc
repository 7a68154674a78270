#include "network/detector/mediapipe_geometry.h"

#include "hand/keypoints2d.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_util.h"

namespace handlabel {
namespace {

constexpr double kPi = 3.14159265358979323846;

// R = 3x, G = 4y, B = 77: bilinear sampling inside the image reproduces a linear function
// of the sampled position exactly.
ImageU8 LinearImage(int w, int h) {
  ImageU8 image(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      image.at(x, y, 0) = static_cast<uint8_t>(3 * x);
      image.at(x, y, 1) = static_cast<uint8_t>(4 * y);
      image.at(x, y, 2) = 77;
    }
  }
  return image;
}

TEST(MediapipeGeometry, PalmAnchorsFollowTheTwoGrids) {
  const auto anchors = MakeSsdAnchors();
  ASSERT_EQ(anchors.size(), 2016u);  // 24x24 cells x 2 + 12x12 cells x 6
  EXPECT_NEAR(anchors[0].x(), 0.5 / 24, 1e-12);
  EXPECT_NEAR(anchors[1].x(), 0.5 / 24, 1e-12);
  EXPECT_NEAR(anchors[2].x(), 1.5 / 24, 1e-12);       // next cell along x
  EXPECT_NEAR(anchors[2 * 24].y(), 1.5 / 24, 1e-12);  // next row
  EXPECT_NEAR(anchors[1152].x(), 0.5 / 12, 1e-12);
  EXPECT_NEAR(anchors[1157].x(), 0.5 / 12, 1e-12);  // six anchors per coarse cell
  EXPECT_NEAR(anchors[1158].x(), 1.5 / 12, 1e-12);
  EXPECT_NEAR(anchors.back().x(), 11.5 / 12, 1e-12);
  EXPECT_NEAR(anchors.back().y(), 11.5 / 12, 1e-12);
}

TEST(MediapipeGeometry, DecodesBoxKeypointsAndSigmoidScore) {
  const std::vector<Eigen::Vector2d> anchors = {{0.25, 0.5}, {0.75, 0.5}, {0.5, 0.5}};
  std::vector<float> boxes(3 * 18, 0.0f);
  std::vector<float> scores = {2.0f, -3.0f, 1000.0f};
  // Anchor 0: centre +19.2 px in x (0.1), size 38.4 x 57.6 px (0.2 x 0.3).
  boxes[0] = 19.2f;
  boxes[1] = -9.6f;
  boxes[2] = 38.4f;
  boxes[3] = 57.6f;
  for (int k = 0; k < kPalmKeypoints; ++k) {
    boxes[4 + 2 * k] = static_cast<float>(k * 1.92);
    boxes[5 + 2 * k] = static_cast<float>(-k * 3.84);
  }
  boxes[2 * 18 + 2] = boxes[2 * 18 + 3] = 19.2f;
  const auto palms = DecodePalms(boxes, scores, anchors);
  ASSERT_EQ(palms.size(), 2u);  // anchor 1 scores sigmoid(-3) < 0.5
  const PalmDetection& p = palms[0];
  EXPECT_NEAR(p.score, 1.0 / (1.0 + std::exp(-2.0)), 1e-9);
  EXPECT_NEAR(p.xmin, 0.25 + 0.1 - 0.1, 1e-6);
  EXPECT_NEAR(p.ymin, 0.5 - 0.05 - 0.15, 1e-6);
  EXPECT_NEAR(p.width, 0.2, 1e-6);
  EXPECT_NEAR(p.height, 0.3, 1e-6);
  for (int k = 0; k < kPalmKeypoints; ++k) {
    EXPECT_NEAR(p.keypoints[k].x(), 0.25 + k * 0.01, 1e-6);
    EXPECT_NEAR(p.keypoints[k].y(), 0.5 - k * 0.02, 1e-6);
  }
  // Clipping at 100 before the sigmoid.
  EXPECT_NEAR(palms[1].score, 1.0 / (1.0 + std::exp(-100.0)), 1e-15);
}

TEST(MediapipeGeometry, DecodeDropsNegativeSizes) {
  const std::vector<Eigen::Vector2d> anchors = {{0.5, 0.5}};
  std::vector<float> boxes(18, 0.0f);
  boxes[2] = -1.0f;
  boxes[3] = 5.0f;
  EXPECT_TRUE(DecodePalms(boxes, {3.0f}, anchors).empty());
}

PalmDetection Box(double xmin, double ymin, double w, double h, double score) {
  PalmDetection d;
  d.xmin = xmin;
  d.ymin = ymin;
  d.width = w;
  d.height = h;
  d.score = score;
  for (int k = 0; k < kPalmKeypoints; ++k)
    d.keypoints[k] = Eigen::Vector2d(xmin + 0.01 * k, ymin);
  return d;
}

TEST(MediapipeGeometry, WeightedNmsAveragesOverlappingBoxesByScore) {
  // a and b overlap with IoU 0.6; c is disjoint; d overlaps a by IoU 0.25 < 0.3.
  const PalmDetection a = Box(0.1, 0.1, 0.2, 0.2, 0.9);
  const PalmDetection b = Box(0.15, 0.1, 0.2, 0.2, 0.6);
  const PalmDetection c = Box(0.6, 0.6, 0.2, 0.2, 0.7);
  const PalmDetection d = Box(0.1, 0.26, 0.2, 0.2, 0.8);
  EXPECT_NEAR(BoxIou(a, b), 0.03 / 0.05, 1e-12);
  EXPECT_NEAR(BoxIou(a, d), 0.008 / 0.072, 1e-12);
  const auto out = WeightedNonMaxSuppression({b, c, a, d}, 0.3);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_DOUBLE_EQ(out[0].score, 0.9);  // the top box's score survives the merge
  EXPECT_NEAR(out[0].xmin, (0.1 * 0.9 + 0.15 * 0.6) / 1.5, 1e-12);
  EXPECT_NEAR(out[0].width, (0.3 * 0.9 + 0.35 * 0.6) / 1.5 - out[0].xmin, 1e-12);
  EXPECT_NEAR(out[0].keypoints[3].x(), (0.13 * 0.9 + 0.18 * 0.6) / 1.5, 1e-12);
  EXPECT_DOUBLE_EQ(out[1].score, 0.8);
  EXPECT_DOUBLE_EQ(out[1].ymin, 0.26);
  EXPECT_DOUBLE_EQ(out[2].score, 0.7);
}

TEST(MediapipeGeometry, LetterboxRemovalInvertsThePadding) {
  // A 400x300 image letterboxed into a square: 50 px bands at top and bottom of 400.
  const RotatedRect whole{200, 150, 400, 300, 0};
  LetterboxPadding pad;
  const RotatedRect padded = PadRoi(whole, 1.0, &pad);
  EXPECT_DOUBLE_EQ(padded.height, 400);
  EXPECT_DOUBLE_EQ(pad.top, 0.125);
  EXPECT_DOUBLE_EQ(pad.left, 0.0);
  // Image point (x, y) normalised sits at (x, 0.125 + 0.75 y) in the square.
  PalmDetection d = Box(0.3, 0.125 + 0.75 * 0.4, 0.2, 0.75 * 0.2, 1.0);
  const PalmDetection r = RemoveLetterbox(d, pad);
  EXPECT_NEAR(r.ymin, 0.4, 1e-12);
  EXPECT_NEAR(r.height, 0.2, 1e-12);
  EXPECT_NEAR(r.xmin, 0.3, 1e-12);
  EXPECT_NEAR(r.keypoints[0].y(), 0.4, 1e-12);
}

TEST(MediapipeGeometry, PalmTilesCoverTheImageAndOverlapByAQuarterTile) {
  const int w = 1920, h = 1080;
  const std::vector<PalmTile> tiles = MakePalmTiles(w, h, 3);
  // Three across the 1080 px side: 1080 = 3 s - 2 (s / 4), s = 432; along 1920 px:
  // ceil((1920 - 432) / 324) + 1 = 6 tiles.
  ASSERT_EQ(tiles.size(), 18u);
  const double side = tiles[0].side;
  EXPECT_NEAR(side, 432, 1e-9);
  for (const PalmTile& t : tiles) {
    EXPECT_GE(t.left, -1e-9);
    EXPECT_GE(t.top, -1e-9);
    EXPECT_LE(t.left + t.side, w + 1e-9);
    EXPECT_LE(t.top + t.side, h + 1e-9);
  }
  // A palm box a quarter tile wide lies whole in some tile wherever it is.
  const double palm = side / 4;
  for (double y = 0; y + palm <= h; y += 7.3) {
    for (double x = 0; x + palm <= w; x += 11.1) {
      bool inside = false;
      for (const PalmTile& t : tiles) {
        inside |= x >= t.left - 1e-9 && y >= t.top - 1e-9 &&
                  x + palm <= t.left + t.side + 1e-9 && y + palm <= t.top + t.side + 1e-9;
      }
      ASSERT_TRUE(inside) << "a " << palm << " px palm at " << x << ", " << y;
    }
  }
  // A square image one tile across is one tile: the image itself.
  const std::vector<PalmTile> one = MakePalmTiles(500, 500, 1);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_DOUBLE_EQ(one[0].side, 500);
  EXPECT_DOUBLE_EQ(one[0].left, 0);
  // Portrait images count the tiles across their width.
  EXPECT_NEAR(MakePalmTiles(1080, 1920, 3)[0].side, 432, 1e-9);
}

TEST(MediapipeGeometry, TileCoordinatesMapToWhereTheTileCropSampled) {
  // Each tensor pixel of a tile's crop holds the linear image function at the image
  // point that TileToImage gives for that pixel's centre (in the tile's [0, 1] frame).
  const ImageU8 image = LinearImage(80, 60);
  const std::vector<PalmTile> tiles = MakePalmTiles(80, 60, 2);
  ASSERT_GT(tiles.size(), 2u);
  const PalmTile& tile = tiles[1];
  const int n = 16;
  const TensorCrop crop =
      CropToTensor(image, tile.ToRect(), n, n, true, BorderMode::kZero);
  EXPECT_DOUBLE_EQ(crop.padding.left + crop.padding.top, 0.0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      PalmDetection d = Box((i + 0.5) / n, (j + 0.5) / n, 0.1, 0.2, 1.0);
      d.keypoints[3] = Eigen::Vector2d((i + 0.5) / n, (j + 0.5) / n);
      const PalmDetection m = TileToImage(d, tile, 80, 60);
      const Eigen::Vector2d corner = NormToPixel({m.xmin, m.ymin}, 80, 60);
      const Eigen::Vector2d kp = NormToPixel(m.keypoints[3], 80, 60);
      const float* v = &crop.values[(j * n + i) * 3];
      ASSERT_NEAR(v[0] * 255.0, 3 * corner.x(), 1e-3) << i << "," << j;
      ASSERT_NEAR(v[1] * 255.0, 4 * corner.y(), 1e-3) << i << "," << j;
      ASSERT_NEAR((kp - corner).norm(), 0, 1e-9);
      // Sizes scale by the tile side over the image size, per axis.
      ASSERT_NEAR(m.width * 80, 0.1 * tile.side, 1e-9);
      ASSERT_NEAR(m.height * 60, 0.2 * tile.side, 1e-9);
    }
  }
}

TEST(MediapipeGeometry, APalmSeenInTwoOverlappingTilesMergesIntoOne) {
  const int w = 1920, h = 1080;
  const std::vector<PalmTile> tiles = MakePalmTiles(w, h, 3);
  const PalmTile& a = tiles[0];
  const PalmTile& b = tiles[1];  // its right neighbour
  ASSERT_LT(b.left, a.left + a.side);
  // A 30 px palm in the overlap of a and b, in image pixels (continuous coordinates).
  const double x = (b.left + a.left + a.side) / 2 - 15, y = 200, size = 30;
  const auto in_tile = [&](const PalmTile& t, double dx, double score) {
    PalmDetection d = Box((x + dx - t.left) / t.side, (y - t.top) / t.side, size / t.side,
                          size / t.side, score);
    return TileToImage(d, t, w, h);
  };
  // The two tiles see it 2 px apart; a palm elsewhere (tile 10) stays its own.
  PalmDetection far = Box(0.4, 0.4, 0.1, 0.1, 0.7);
  const std::vector<PalmDetection> merged = WeightedNonMaxSuppression(
      {in_tile(a, -1, 0.6), in_tile(b, 1, 0.9), TileToImage(far, tiles[10], w, h)});
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_DOUBLE_EQ(merged[0].score, 0.9);
  // The score-weighted mean: (0.6 (x - 1) + 0.9 (x + 1)) / 1.5 = x + 0.2.
  EXPECT_NEAR(merged[0].xmin * w, x + 0.2, 1e-9);
  EXPECT_NEAR(merged[0].ymin * h, y, 1e-9);
  EXPECT_NEAR(merged[0].width * w, size, 1e-9);
  EXPECT_DOUBLE_EQ(merged[1].score, 0.7);
}

TEST(MediapipeGeometry, UprightPalmGivesAnUnrotatedSquareRoiShiftedToTheFingers) {
  // 640x480 image; palm box 64x48 px centred at (320, 240); middle MCP straight above
  // the wrist.
  PalmDetection palm = Box(0.45, 0.45, 0.1, 0.1, 0.9);
  palm.keypoints[0] = {0.5, 0.55};
  palm.keypoints[2] = {0.5, 0.45};
  const NormalizedRect roi = HandRoiFromPalm(palm, 640, 480);
  EXPECT_NEAR(roi.rotation, 0.0, 1e-12);
  EXPECT_NEAR(roi.x_center, 0.5, 1e-12);
  EXPECT_NEAR(roi.y_center, 0.5 - 0.05, 1e-12);  // half a box height towards the fingers
  const RotatedRect px = roi.ToPixels(640, 480);
  EXPECT_NEAR(px.width, 64 * 2.6, 1e-9);  // square on the long side
  EXPECT_NEAR(px.height, 64 * 2.6, 1e-9);
}

TEST(MediapipeGeometry, PalmPointingRightRotatesTheRoiAndShiftsRight) {
  PalmDetection palm = Box(0.4, 0.4, 0.2, 0.2, 0.9);
  palm.keypoints[0] = {0.45, 0.5};
  palm.keypoints[2] = {0.55, 0.5};
  const NormalizedRect roi = HandRoiFromPalm(palm, 500, 500);
  EXPECT_NEAR(roi.rotation, kPi / 2, 1e-12);
  EXPECT_NEAR(roi.x_center, 0.5 + 0.1, 1e-12);
  EXPECT_NEAR(roi.y_center, 0.5, 1e-12);
  // The crop's "up" (towards the fingers) is the image's +x: crop point (0.5, 0) maps
  // to the right edge of the ROI.
  const Eigen::Vector2d top = ProjectCropPoint({0.5, 0.0}, roi, {});
  EXPECT_NEAR(top.x(), roi.x_center + roi.width / 2, 1e-12);
  EXPECT_NEAR(top.y(), 0.5, 1e-12);
}

TEST(MediapipeGeometry, CropSamplesWhereLandmarkProjectionMapsBack) {
  // A rotated ROI well inside the image: each tensor pixel holds the linear image
  // function at the image point that ProjectCropPoint gives for that pixel's centre.
  const ImageU8 image = LinearImage(80, 60);
  NormalizedRect roi;
  roi.x_center = 0.5;
  roi.y_center = 0.45;
  roi.width = 30.0 / 80;
  roi.height = 30.0 / 60;
  roi.rotation = 0.4;
  const int n = 16;
  const TensorCrop crop =
      CropToTensor(image, roi.ToPixels(80, 60), n, n, true, BorderMode::kReplicate);
  EXPECT_DOUBLE_EQ(crop.padding.left + crop.padding.top, 0.0);  // square in pixels
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d norm =
          ProjectCropPoint({(i + 0.5) / n, (j + 0.5) / n}, roi, crop.padding);
      const Eigen::Vector2d px = NormToPixel(norm, 80, 60);
      const float* v = &crop.values[(j * n + i) * 3];
      ASSERT_NEAR(v[0] * 255.0, 3 * px.x(), 1e-3) << i << "," << j;
      ASSERT_NEAR(v[1] * 255.0, 4 * px.y(), 1e-3) << i << "," << j;
      ASSERT_NEAR(v[2] * 255.0, 77, 1e-3);
    }
  }
}

TEST(MediapipeGeometry, PalmLetterboxIsZeroAndEdgesReplicate) {
  const ImageU8 image = LinearImage(40, 20);
  const RotatedRect whole{20, 10, 40, 20, 0};
  const TensorCrop zero = CropToTensor(image, whole, 8, 8, true, BorderMode::kZero);
  EXPECT_DOUBLE_EQ(zero.padding.top, 0.25);
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(zero.values[(0 * 8 + i) * 3 + 2], 0.0f);                // top band
    EXPECT_EQ(zero.values[(7 * 8 + i) * 3 + 2], 0.0f);                // bottom band
    EXPECT_NEAR(zero.values[(3 * 8 + i) * 3 + 2] * 255.0, 77, 1e-4);  // image rows
  }
  // Replicate: a ROI hanging off the left edge repeats the first column (R = 0).
  const RotatedRect off{-10, 10, 10, 10, 0};
  const TensorCrop rep = CropToTensor(image, off, 4, 4, false, BorderMode::kReplicate);
  for (int k = 0; k < 16; ++k) EXPECT_EQ(rep.values[k * 3], 0.0f);
}

// An upright hand: wrist at the bottom, fingers straight up, in pixels.
KeypointPixels UprightHand() {
  KeypointPixels uv;
  uv.row(0) << 100, 200;
  for (int f = 0; f < 5; ++f) {
    const double x = 70 + 15 * f;
    for (int j = 0; j < 4; ++j) uv.row(1 + 4 * f + j) << x, 160 - 20 * j;
  }
  return uv;
}

TEST(MediapipeGeometry, KeypointRoiIsUprightForAnUprightHand) {
  const NormalizedRect roi = RoiFromKeypoints(UprightHand(), 400, 300);
  EXPECT_NEAR(roi.rotation, 0.0, 1e-12);
  // Box of joints 0,1,2,3,5,6,9,10,13,14,17,18: x 70..130, y 120..200 (MediaPipe's
  // continuous coordinates are ours + 0.5).
  EXPECT_NEAR(roi.x_center * 400, 100.5, 1e-9);
  EXPECT_NEAR(roi.y_center * 300, 160.5 - 8.0, 1e-9);  // 0.1 box heights to the fingers
  EXPECT_NEAR(roi.width * 400, 160.0, 1e-9);           // 2 x the 80 px long side
  EXPECT_NEAR(roi.height * 300, 160.0, 1e-9);
}

TEST(MediapipeGeometry, KeypointRoiTurnsWithTheHand) {
  const KeypointPixels upright = UprightHand();
  const NormalizedRect base = RoiFromKeypoints(upright, 400, 300);
  const double angle = 0.7;
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(angle).toRotationMatrix();
  const Eigen::Vector2d pivot(150, 120);
  KeypointPixels turned;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    turned.row(k) = (pivot + R * (upright.row(k).transpose() - pivot)).transpose();
  }
  const NormalizedRect roi = RoiFromKeypoints(turned, 400, 300);
  EXPECT_NEAR(roi.rotation, angle, 1e-9);
  const Eigen::Vector2d base_centre(base.x_center * 400 - 0.5, base.y_center * 300 - 0.5);
  const Eigen::Vector2d centre = pivot + R * (base_centre - pivot);
  EXPECT_NEAR(roi.x_center * 400 - 0.5, centre.x(), 1e-6);
  EXPECT_NEAR(roi.y_center * 300 - 0.5, centre.y(), 1e-6);
  EXPECT_NEAR(roi.width * 400, base.width * 400, 1e-6);
}

}  // namespace
}  // namespace handlabel
