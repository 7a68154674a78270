#include "network/detector/detector_overlay.h"

#include <cmath>
#include <cstdio>

#include "hand/hand_skeleton.h"

namespace handlabel {
namespace {

std::string Upper(std::string text) {
  for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

void DrawPolygon(ImageU8* rgb, const std::vector<Eigen::Vector2d>& corners,
                 const Rgb& color, int thickness) {
  for (size_t i = 0; i < corners.size(); ++i) {
    DrawLine(rgb, corners[i], corners[(i + 1) % corners.size()], color, thickness);
  }
}

}  // namespace

std::vector<Eigen::Vector2d> RoiCornersPx(const NormalizedRect& roi, int width,
                                          int height) {
  // Normalised coordinates put 0 at the image's left edge; handlabel pixels put 0 at
  // the first pixel's centre: half a pixel apart.
  const RotatedRect r = roi.ToPixels(width, height);
  const Eigen::Vector2d centre(r.x_center - 0.5, r.y_center - 0.5);
  const Eigen::Vector2d ax(std::cos(r.rotation), std::sin(r.rotation));
  const Eigen::Vector2d ay(-std::sin(r.rotation), std::cos(r.rotation));
  const double hw = 0.5 * r.width, hh = 0.5 * r.height;
  return {centre - hw * ax - hh * ay, centre + hw * ax - hh * ay,
          centre + hw * ax + hh * ay, centre - hw * ax + hh * ay};
}

std::string DetectionCaption(const ViewHandResult& view) {
  if (!view.detected) return "NONE: " + Upper(view.reason);
  char presence[32];
  std::snprintf(presence, sizeof(presence), " P%.2f", view.hand.presence);
  return Upper(view.source) + presence;
}

void DrawHandDetection(const ViewHandResult& view, ImageU8* rgb) {
  const int w = rgb->width, h = rgb->height;
  const int scale = std::max(1, static_cast<int>(std::lround(w / 640.0)));
  for (const PalmDetection& palm : view.palms) {
    const double x0 = palm.xmin * w - 0.5, y0 = palm.ymin * h - 0.5;
    const double x1 = x0 + palm.width * w, y1 = y0 + palm.height * h;
    DrawPolygon(rgb, {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, kPalmBoxColor, scale);
  }
  if (view.detected) {
    DrawPolygon(rgb, RoiCornersPx(view.hand.roi, w, h), kRoiColor, scale);
    const Keypoints2d& kp = view.keypoints;
    for (int k = 1; k < kNumHandKeypoints; ++k) {
      const int parent = kSnapParents[k];
      if (kp.confidence(k) > 0 && kp.confidence(parent) > 0) {
        DrawLine(rgb, kp.uv_px.row(parent).transpose(), kp.uv_px.row(k).transpose(),
                 SnapKeypointColor(k), scale);
      }
    }
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!(kp.confidence(k) > 0)) continue;
      // Radius 1.5-4 px (x scale) with the confidence.
      const double radius = scale * (1.5 + 2.5 * std::clamp(kp.confidence(k), 0.0, 1.0));
      DrawDisc(rgb, kp.uv_px.row(k).transpose(), radius, SnapKeypointColor(k));
    }
  }
  DrawText(rgb, 4 * scale, 4 * scale, DetectionCaption(view),
           view.detected ? kCaptionColor : kNoHandColor, 2 * scale);
}

}  // namespace handlabel
