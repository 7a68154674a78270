#include "network/poem/hand_crop.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

void HandCropOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "crop_size", crop_size, 8);
  RequireGreater(source, "box_scale", box_scale, 0);
  RequireGreater(source, "min_side_px", min_side_px, 0);
  RequireAtLeast(source, "min_keypoints", min_keypoints, 2);
  RequireGreater(source, "std", std, 0);
}

CropWindow CropFromBox(const Eigen::Vector2d& box_min, const Eigen::Vector2d& box_max,
                       const HandCropOptions& options) {
  CropWindow w;
  w.center = 0.5 * (box_min + box_max);
  const double longer = (box_max - box_min).cwiseAbs().maxCoeff();
  w.side = std::max(options.box_scale * longer, options.min_side_px);
  return w;
}

std::optional<CropWindow> CropFromKeypoints(const Keypoints2d& keypoints,
                                            const HandCropOptions& options) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY);
  Eigen::Vector2d hi = Eigen::Vector2d::Constant(-INFINITY);
  int used = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const Eigen::Vector2d uv = keypoints.uv_px.row(k).transpose();
    if (!(keypoints.confidence(k) >= options.min_confidence) || !uv.allFinite()) continue;
    lo = lo.cwiseMin(uv);
    hi = hi.cwiseMax(uv);
    ++used;
  }
  if (used < options.min_keypoints) return std::nullopt;
  return CropFromBox(lo, hi, options);
}

std::optional<CropWindow> CropFromPrior(const Camera& camera,
                                        const std::vector<Eigen::Vector3d>& points_in_cam,
                                        const HandCropOptions& options) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY);
  Eigen::Vector2d hi = Eigen::Vector2d::Constant(-INFINITY);
  int used = 0;
  for (const Eigen::Vector3d& p : points_in_cam) {
    Eigen::Vector2d uv;
    if (!camera.Project(p, &uv) || !uv.allFinite()) continue;
    lo = lo.cwiseMin(uv);
    hi = hi.cwiseMax(uv);
    ++used;
  }
  if (used < 2) return std::nullopt;
  // The box must overlap the image.
  if (hi.x() < -0.5 || hi.y() < -0.5 || lo.x() > camera.width() - 0.5 ||
      lo.y() > camera.height() - 0.5) {
    return std::nullopt;
  }
  return CropFromBox(lo, hi, options);
}

CropWindow WholeImageCrop(const Camera& camera) {
  CropWindow w;
  w.center = Eigen::Vector2d(0.5 * (camera.width() - 1), 0.5 * (camera.height() - 1));
  w.side = std::max(camera.width(), camera.height());
  return w;
}

Eigen::Matrix3d CropIntrinsics(const Camera& camera, const CropWindow& window,
                               int crop_size) {
  // Source pixel x maps to crop pixel s (x - c) + S/2 (pinhole part of the camera).
  const double s = crop_size / window.side;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = s * camera.fx();
  K(1, 1) = s * camera.fy();
  K(0, 2) = s * (camera.cx() - window.center.x()) + 0.5 * crop_size;
  K(1, 2) = s * (camera.cy() - window.center.y()) + 0.5 * crop_size;
  return K;
}

std::vector<float> WarpCrop(const RgbImageView& image, const Camera& camera,
                            const CropWindow& window, const HandCropOptions& options) {
  if (image.width != camera.width() || image.height != camera.height() || !image.data) {
    throw InputError("hand crop", "image",
                     "the camera's size " + std::to_string(camera.width()) + "x" +
                         std::to_string(camera.height()),
                     std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  const int S = options.crop_size;
  const Eigen::Matrix3d K = CropIntrinsics(camera, window, S);
  const double inv_std = 1.0 / options.std;
  std::vector<float> out(3 * S * S, 0.0f);
  const float zero = static_cast<float>((0.0 - options.mean) * inv_std);
  for (int y = 0; y < S; ++y) {
    for (int x = 0; x < S; ++x) {
      // Ray of the crop pixel, then the source pixel with the source distortion.
      const Eigen::Vector2d xy((x - K(0, 2)) / K(0, 0), (y - K(1, 2)) / K(1, 1));
      const Eigen::Vector2d uv = camera.ImageFromNormalized(xy);
      const double fx = std::floor(uv.x()), fy = std::floor(uv.y());
      const double ax = uv.x() - fx, ay = uv.y() - fy;
      const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
      double acc[3] = {0, 0, 0};
      bool any = false;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int sx = x0 + dx, sy = y0 + dy;
          if (sx < 0 || sy < 0 || sx >= image.width || sy >= image.height) continue;
          const double w = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
          const uint8_t* p =
              image.data + (static_cast<size_t>(sy) * image.width + sx) * 3;
          for (int c = 0; c < 3; ++c) acc[c] += w * p[c];
          any = true;
        }
      }
      for (int c = 0; c < 3; ++c) {
        out[(static_cast<size_t>(c) * S + y) * S + x] =
            any ? static_cast<float>((acc[c] / 255.0 - options.mean) * inv_std) : zero;
      }
    }
  }
  return out;
}

ViewCrop CropForView(const RgbImageView& image, const Camera& camera,
                     const HandEvidence& evidence, const HandCropOptions& options) {
  options.Check("hand crop options");
  ViewCrop crop;
  std::optional<CropWindow> window;
  if (evidence.keypoints) {
    window = CropFromKeypoints(*evidence.keypoints, options);
    crop.source = "keypoints";
  }
  if (!window && evidence.box) {
    window = CropFromBox(evidence.box->first, evidence.box->second, options);
    crop.source = "box";
  }
  if (!window && !evidence.prior_points_in_cam.empty()) {
    window = CropFromPrior(camera, evidence.prior_points_in_cam, options);
    crop.source = "prior";
  }
  // Evidence that failed to find the hand marks the view as not visible; no evidence
  // at all means the whole image is the intended input.
  const bool had_evidence = evidence.keypoints.has_value() || evidence.box.has_value() ||
                            !evidence.prior_points_in_cam.empty();
  crop.hand_visible = window.has_value() || !had_evidence;
  if (!window) {
    window = WholeImageCrop(camera);
    crop.source = "whole image";
  }
  crop.window = *window;
  crop.intrinsics = CropIntrinsics(camera, crop.window, options.crop_size);
  crop.pixels = WarpCrop(image, camera, crop.window, options);
  return crop;
}

MaskImage CropMaskToImage(const Eigen::MatrixXf& probability, int cell,
                          const Eigen::Matrix3d& K, const Camera& camera,
                          double threshold) {
  const int M = static_cast<int>(probability.rows());
  HL_CHECK(M > 0 && probability.cols() == M && cell > 0, "a square, non-empty grid");
  const double side = static_cast<double>(M) * cell;
  MaskImage mask = MaskImage::Zero(camera.height(), camera.width());
  // Image box of the crop: its border rays, projected (bent by the distortion).
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY);
  Eigen::Vector2d hi = Eigen::Vector2d::Constant(-INFINITY);
  constexpr int kBorderSamples = 32;
  for (int i = 0; i <= kBorderSamples; ++i) {
    const double t = -0.5 + side * i / kBorderSamples;
    for (const Eigen::Vector2d& c :
         {Eigen::Vector2d(t, -0.5), Eigen::Vector2d(t, side - 0.5),
          Eigen::Vector2d(-0.5, t), Eigen::Vector2d(side - 0.5, t)}) {
      const Eigen::Vector2d xy((c.x() - K(0, 2)) / K(0, 0), (c.y() - K(1, 2)) / K(1, 1));
      const Eigen::Vector2d uv = camera.ImageFromNormalized(xy);
      lo = lo.cwiseMin(uv);
      hi = hi.cwiseMax(uv);
    }
  }
  const int x_begin = std::max(0, static_cast<int>(std::floor(lo.x())) - 1);
  const int y_begin = std::max(0, static_cast<int>(std::floor(lo.y())) - 1);
  const int x_end = std::min(camera.width(), static_cast<int>(std::ceil(hi.x())) + 2);
  const int y_end = std::min(camera.height(), static_cast<int>(std::ceil(hi.y())) + 2);
  // Cell (i, j) covers crop pixels [cell j, cell j + cell): its centre is at crop
  // coordinate cell j + (cell - 1) / 2 (pixel centres at integers).
  const double centre = 0.5 * (cell - 1);
  for (int y = y_begin; y < y_end; ++y) {
    for (int x = x_begin; x < x_end; ++x) {
      const Eigen::Vector2d xy = camera.NormalizedFromImage(Eigen::Vector2d(x, y));
      const double cx = K(0, 0) * xy.x() + K(0, 2), cy = K(1, 1) * xy.y() + K(1, 2);
      if (cx < -0.5 || cy < -0.5 || cx > side - 0.5 || cy > side - 0.5) continue;
      const double gx = std::clamp((cx - centre) / cell, 0.0, M - 1.0);
      const double gy = std::clamp((cy - centre) / cell, 0.0, M - 1.0);
      const int j0 = std::min(static_cast<int>(gx), std::max(M - 2, 0));
      const int i0 = std::min(static_cast<int>(gy), std::max(M - 2, 0));
      const int j1 = std::min(j0 + 1, M - 1), i1 = std::min(i0 + 1, M - 1);
      const double ax = gx - j0, ay = gy - i0;
      const double p =
          (1 - ay) * ((1 - ax) * probability(i0, j0) + ax * probability(i0, j1)) +
          ay * ((1 - ax) * probability(i1, j0) + ax * probability(i1, j1));
      if (p > threshold) mask(y, x) = 255;
    }
  }
  return mask;
}

}  // namespace handlabel
