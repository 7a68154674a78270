#include "network/poem/hand_crop.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace handlabel {
namespace {

// R = x, G = y (x, y < 256): bilinear sampling reproduces the sampled position exactly.
std::vector<uint8_t> GradientImage(int w, int h) {
  std::vector<uint8_t> img(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &img[(static_cast<size_t>(y) * w + x) * 3];
      p[0] = static_cast<uint8_t>(x);
      p[1] = static_cast<uint8_t>(y);
      p[2] = 128;
    }
  return img;
}

TEST(HandCrop, IntrinsicsMapProjectionsIntoTheCrop) {
  const Camera cam = Camera::Pinhole(500, 510, 320, 240, 640, 480);
  HandCropOptions o;
  o.crop_size = 128;
  const CropWindow w = CropFromBox({300, 200}, {360, 250}, o);
  EXPECT_DOUBLE_EQ(w.side, 120);
  const Eigen::Matrix3d K = CropIntrinsics(cam, w, o.crop_size);
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d X =
        testing::RandomVector3(-0.1, 0.1) + Eigen::Vector3d(0, 0, 0.7);
    Eigen::Vector2d uv;
    ASSERT_TRUE(cam.Project(X, &uv));
    const Eigen::Vector3d c = K * X;
    const Eigen::Vector2d expected = (uv - w.center) * (o.crop_size / w.side) +
                                     Eigen::Vector2d::Constant(o.crop_size / 2.0);
    EXPECT_NEAR(c.x() / c.z(), expected.x(), 1e-9);
    EXPECT_NEAR(c.y() / c.z(), expected.y(), 1e-9);
  }
}

TEST(HandCrop, WarpSamplesWhereTheCropRayLandsWithDistortion) {
  const Camera cam(CameraModelId::kOpenCV, 200, 150,
                   {180, 185, 100, 75, -0.2, 0.05, 0.001, -0.002});
  const std::vector<uint8_t> img = GradientImage(200, 150);
  HandCropOptions o;
  o.crop_size = 32;
  o.mean = 0;
  o.std = 1;
  CropWindow w;
  w.center = {90, 80};
  w.side = 64;
  const std::vector<float> crop = WarpCrop({200, 150, img.data()}, cam, w, o);
  const Eigen::Matrix3d K = CropIntrinsics(cam, w, o.crop_size);
  for (int y = 0; y < 32; y += 5) {
    for (int x = 0; x < 32; x += 7) {
      // The crop pixel's ray, projected by the distorted source camera.
      const Eigen::Vector3d ray = K.inverse() * Eigen::Vector3d(x, y, 1);
      Eigen::Vector2d uv;
      ASSERT_TRUE(cam.Project(ray, &uv));
      EXPECT_NEAR(crop[(0 * 32 + y) * 32 + x] * 255.0, uv.x(), 1e-3);
      EXPECT_NEAR(crop[(1 * 32 + y) * 32 + x] * 255.0, uv.y(), 1e-3);
    }
  }
}

TEST(HandCrop, OutsideTheImageIsBlackAfterNormalisation) {
  const Camera cam = Camera::Pinhole(100, 100, 50, 50, 100, 100);
  const std::vector<uint8_t> img(100 * 100 * 3, 255);
  HandCropOptions o;
  o.crop_size = 16;
  CropWindow w;
  w.center = {500, 500};  // far outside
  w.side = 20;
  const std::vector<float> crop = WarpCrop({100, 100, img.data()}, cam, w, o);
  for (float v : crop) EXPECT_FLOAT_EQ(v, -0.5f);
}

TEST(HandCrop, ChoosesEvidenceInOrderAndMarksMissedViews) {
  const Camera cam = Camera::Pinhole(300, 300, 160, 120, 320, 240);
  const std::vector<uint8_t> img(320 * 240 * 3, 0);
  const RgbImageView view{320, 240, img.data()};
  HandCropOptions o;
  o.crop_size = 16;
  HandEvidence e;
  e.keypoints.emplace();  // four detected keypoints, the others not detected
  e.keypoints->uv_px.topRows(4) << 100, 100, 120, 110, 110, 130, 105, 90;
  e.keypoints->confidence.head(4) << 0.9, 0.8, 0.7, 0.9;
  ViewCrop c = CropForView(view, cam, e, o);
  EXPECT_EQ(c.source, "keypoints");
  EXPECT_TRUE(c.hand_visible);
  EXPECT_NEAR(c.window.center.x(), 110, 1e-9);
  EXPECT_NEAR(c.window.side, 80, 1e-9);  // 2 x the 40 px box

  e.keypoints->confidence.head(4) << 0.9, 0.1, 0.1, 0.1;  // too few confident ones
  e.prior_points_in_cam = {{0, 0, 0.5}, {0.05, 0.02, 0.5}};
  c = CropForView(view, cam, e, o);
  EXPECT_EQ(c.source, "prior");
  EXPECT_TRUE(c.hand_visible);

  e.prior_points_in_cam = {{0, 0, -0.5}, {0.05, 0.02, -0.5}};  // behind the camera
  c = CropForView(view, cam, e, o);
  EXPECT_EQ(c.source, "whole image");
  EXPECT_FALSE(c.hand_visible);
  EXPECT_DOUBLE_EQ(c.window.side, 320);

  c = CropForView(view, cam, HandEvidence(), o);  // no evidence: the whole image is meant
  EXPECT_TRUE(c.hand_visible);
  EXPECT_EQ(c.source, "whole image");
  // The window is the image's square: its centre pixel maps to the crop's centre and
  // the crop's focal length shrinks by the window's 320 px over the crop's 16.
  EXPECT_DOUBLE_EQ(c.window.center.x(), 159.5);
  EXPECT_DOUBLE_EQ(c.window.center.y(), 119.5);
  EXPECT_DOUBLE_EQ(c.window.side, 320);
  EXPECT_NEAR(c.intrinsics(0, 0), 300.0 * 16 / 320, 1e-9);
  const Eigen::Vector3d centre =
      c.intrinsics * Eigen::Vector3d((159.5 - 160) / 300, (119.5 - 120) / 300, 1);
  EXPECT_NEAR(centre.x(), 8, 1e-9);
  EXPECT_NEAR(centre.y(), 8, 1e-9);
}

// A mask predicted on the crop grid comes back to the image where it was: warp a
// disc mask into the crop (WarpCrop, the network's input path), pool it to 4 x 4
// cells as the mask head's target, map it back and compare with the disc.
TEST(HandCrop, CropMaskMapsBackOntoTheImageMask) {
  const Camera cam(CameraModelId::kOpenCV, 320, 240,
                   {300, 305, 160, 120, -0.25, 0.06, 0.001, -0.002});
  const Eigen::Vector2d disc(210, 90);  // off-centre: distortion bends it
  const double radius = 30;
  std::vector<uint8_t> img(320 * 240 * 3, 0);
  MaskImage truth = MaskImage::Zero(240, 320);
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x)
      if ((Eigen::Vector2d(x, y) - disc).norm() < radius) {
        truth(y, x) = 255;
        for (int c = 0; c < 3; ++c) img[(y * 320 + x) * 3 + c] = 255;
      }
  HandCropOptions o;
  o.crop_size = 128;
  o.mean = 0;
  o.std = 1;
  const CropWindow w = CropFromBox(disc.array() - radius, disc.array() + radius, o);
  const std::vector<float> crop = WarpCrop({320, 240, img.data()}, cam, w, o);
  const int M = 32;
  Eigen::MatrixXf cells = Eigen::MatrixXf::Zero(M, M);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) cells(y / 4, x / 4) += crop[y * 128 + x] / 16.0f;
  const MaskImage back =
      CropMaskToImage(cells, 4, CropIntrinsics(cam, w, o.crop_size), cam);
  ASSERT_EQ(back.rows(), 240);
  ASSERT_EQ(back.cols(), 320);
  int inter = 0, uni = 0, far_set = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      const bool a = truth(y, x), b = back(y, x);
      inter += a && b;
      uni += a || b;
      // Nothing outside the crop window (side 2 x 60 px around the disc).
      far_set += b && (Eigen::Vector2d(x, y) - disc).norm() > 2 * radius;
    }
  EXPECT_GT(static_cast<double>(inter) / uni, 0.95);
  EXPECT_EQ(far_set, 0);
  // A wrong intrinsic (shifted crop) moves it: the test sees the geometry.
  Eigen::Matrix3d shifted = CropIntrinsics(cam, w, o.crop_size);
  shifted(0, 2) += 20;
  const MaskImage moved = CropMaskToImage(cells, 4, shifted, cam);
  int moved_inter = 0, moved_uni = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      moved_inter += truth(y, x) && moved(y, x);
      moved_uni += truth(y, x) || moved(y, x);
    }
  EXPECT_LT(static_cast<double>(moved_inter) / moved_uni, 0.8);
}

}  // namespace
}  // namespace handlabel
