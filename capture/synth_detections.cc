#include "capture/synth_detections.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "image/distance_transform.h"
#include "image/mask_image.h"

namespace handlabel {
namespace {

// Square erosion (radius < 0) or dilation (radius > 0), separable.
ImageU8 Morph(const ImageU8& mask, int radius) {
  if (radius == 0) return mask;
  const bool dilate = radius > 0;
  const int r = std::abs(radius);
  const int w = mask.width, h = mask.height;
  ImageU8 tmp(w, h, 1), out(w, h, 1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool any = !dilate;
      for (int d = -r; d <= r; ++d) {
        const int xx = std::clamp(x + d, 0, w - 1);
        const bool on = mask.at(xx, y) != 0;
        any = dilate ? (any || on) : (any && on);
      }
      tmp.at(x, y) = any ? 255 : 0;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool any = !dilate;
      for (int d = -r; d <= r; ++d) {
        const int yy = std::clamp(y + d, 0, h - 1);
        const bool on = tmp.at(x, yy) != 0;
        any = dilate ? (any || on) : (any && on);
      }
      out.at(x, y) = any ? 255 : 0;
    }
  }
  return out;
}

}  // namespace

void DetectionNoiseOptions::Check(const std::string& source) const {
  RequireInRange(source, "keypoint_sigma_px", keypoint_sigma_px, 0, 1000);
  for (double rate : {outlier_rate, dropout_rate, occluded_dropout_rate}) {
    RequireInRange(source, "outlier_rate/dropout_rate", rate, 0, 1,
                   "probabilities in [0, 1]");
  }
  RequireAtLeast(source, "object_sigma_per_px", object_sigma_per_px, 0);
  RequireGreater(source, "object_confidence_px", object_confidence_px, 0);
  RequireAtLeast(source, "object_depth_cap_px", object_depth_cap_px, 0);
  if (mask_morph_radius < 0 || mask_morph_radius > 50 || mask_blobs < 0) {
    throw InputError(source, "mask_morph_radius/mask_blobs", "0..50 and >= 0");
  }
}

std::array<double, kNumHandKeypoints> DepthBehindObjects(const SynthView& view,
                                                         double cap_px) {
  std::array<double, kNumHandKeypoints> depth{};
  bool any = false;
  for (int k = 0; k < kNumHandKeypoints; ++k) any |= view.behind_object[k];
  if (!any) return depth;
  const DistanceImage to_hand = DistanceToMask(MaskFromImage(view.hand_mask));
  const int w = view.hand_mask.width, h = view.hand_mask.height;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (!view.behind_object[k]) continue;
    const int x =
        std::clamp(static_cast<int>(std::lround(view.keypoints(k, 0))), 0, w - 1);
    const int y =
        std::clamp(static_cast<int>(std::lround(view.keypoints(k, 1))), 0, h - 1);
    depth[k] = std::min(to_hand(y, x), cap_px);  // +inf without hand pixels
  }
  return depth;
}

ViewDetections SimulateDetections(const SynthView& view, const DetectionNoiseOptions& o,
                                  std::mt19937_64& rng) {
  ViewDetections det;
  const std::array<double, kNumHandKeypoints> depth =
      DepthBehindObjects(view, o.object_depth_cap_px);
  const double nan = std::nan("");
  det.keypoints.uv_px.setConstant(nan);
  // The hand's box from in-frame keypoints, for outliers.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (view.visibility[k] == kOutOfFrame) continue;
    lo = lo.cwiseMin(view.keypoints.row(k).transpose());
    hi = hi.cwiseMax(view.keypoints.row(k).transpose());
  }
  const Eigen::Vector2d centre = 0.5 * (lo + hi), half = 0.75 * (hi - lo);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    // Draw every random number for every keypoint so that one keypoint's fate does not
    // shift the others' (stable when options change).
    const double u_drop = Uniform(rng, 0, 1), u_out = Uniform(rng, 0, 1);
    const double nx = gauss(rng), ny = gauss(rng);
    const double ox = Uniform(rng, -1, 1), oy = Uniform(rng, -1, 1);
    const double u_conf = Uniform(rng, 0, 1);
    const int vis = view.visibility[k];
    if (vis == kOutOfFrame) continue;
    const double drop = vis == kVisible ? o.dropout_rate : o.occluded_dropout_rate;
    if (u_drop < drop) continue;
    if (u_out < o.outlier_rate) {
      det.keypoints.uv_px(k, 0) =
          std::clamp(centre.x() + ox * half.x(), 0.0, view.rgb.width - 1.0);
      det.keypoints.uv_px(k, 1) =
          std::clamp(centre.y() + oy * half.y(), 0.0, view.rgb.height - 1.0);
      det.keypoints.confidence[k] = 0.1 + 0.5 * u_conf;
      continue;
    }
    const double sigma = o.keypoint_sigma_px * (vis == kVisible ? 1.0 : 2.0) +
                         o.object_sigma_per_px * depth[k];
    det.keypoints.uv_px(k, 0) = view.keypoints(k, 0) + sigma * nx;
    det.keypoints.uv_px(k, 1) = view.keypoints(k, 1) + sigma * ny;
    det.keypoints.confidence[k] =
        vis == kVisible
            ? 0.6 + 0.4 * u_conf
            : (0.2 + 0.4 * u_conf) / (1.0 + depth[k] / o.object_confidence_px);
  }

  // Noisy mask.
  const int radius = o.mask_morph_radius > 0
                         ? static_cast<int>(std::floor(Uniform(rng, -o.mask_morph_radius,
                                                               o.mask_morph_radius + 1)))
                         : 0;
  det.mask = Morph(view.hand_mask, radius);
  const int w = det.mask.width, h = det.mask.height;
  std::vector<int> boundary;  // pixel indices on the mask's edge
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      const uint8_t c = det.mask.at(x, y);
      if (c != det.mask.at(x + 1, y) || c != det.mask.at(x, y + 1)) {
        boundary.push_back(y * w + x);
      }
    }
  }
  const int blobs = static_cast<int>(Uniform(rng, 0, o.mask_blobs + 1));
  for (int b = 0; b < blobs && !boundary.empty(); ++b) {
    const int at =
        boundary[static_cast<size_t>(Uniform(rng, 0, boundary.size())) % boundary.size()];
    const double cx = at % w, cy = at / w;
    const double rx = Uniform(rng, 1.5, 0.02 * w + 2),
                 ry = Uniform(rng, 1.5, 0.02 * h + 2);
    const uint8_t value = Uniform(rng, 0, 1) < 0.5 ? 0 : 255;
    for (int y = std::max(0, static_cast<int>(cy - ry));
         y <= std::min(h - 1, static_cast<int>(cy + ry)); ++y) {
      for (int x = std::max(0, static_cast<int>(cx - rx));
           x <= std::min(w - 1, static_cast<int>(cx + rx)); ++x) {
        const double u = (x - cx) / rx, v = (y - cy) / ry;
        if (u * u + v * v <= 1) det.mask.at(x, y) = value;
      }
    }
  }
  return det;
}

}  // namespace handlabel
