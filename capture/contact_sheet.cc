#include "capture/contact_sheet.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/mask_outline.h"

namespace handlabel {
namespace {

// SNAP skeleton: (parent, child) pairs, with one colour per finger.
constexpr int kBones[20][2] = {{0, 1},   {1, 2},   {2, 3},   {3, 4},   {0, 5},
                               {5, 6},   {6, 7},   {7, 8},   {0, 9},   {9, 10},
                               {10, 11}, {11, 12}, {0, 13},  {13, 14}, {14, 15},
                               {15, 16}, {0, 17},  {17, 18}, {18, 19}, {19, 20}};
constexpr uint8_t kFingerColors[5][3] = {
    {255, 60, 60}, {255, 200, 0}, {60, 220, 60}, {40, 160, 255}, {200, 80, 255}};

int FingerOf(int keypoint) { return keypoint == 0 ? 0 : (keypoint - 1) / 4; }

void PutPixel(ImageU8* img, int x, int y, const uint8_t* c) {
  if (!img->Contains(x, y)) return;
  for (int k = 0; k < 3; ++k) img->at(x, y, k) = c[k];
}

void DrawLine(ImageU8* img, double x0, double y0, double x1, double y1,
              const uint8_t* c) {
  const int steps = static_cast<int>(std::max(std::abs(x1 - x0), std::abs(y1 - y0))) + 1;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    PutPixel(img, static_cast<int>(std::lround(x0 + t * (x1 - x0))),
             static_cast<int>(std::lround(y0 + t * (y1 - y0))), c);
  }
}

void DrawDot(ImageU8* img, double x, double y, int r, const uint8_t* c, bool filled) {
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int d2 = dx * dx + dy * dy;
      if (d2 > r * r || (!filled && d2 < (r - 1) * (r - 1))) continue;
      PutPixel(img, static_cast<int>(std::lround(x)) + dx,
               static_cast<int>(std::lround(y)) + dy, c);
    }
  }
}

}  // namespace

void ContactSheetOptions::Check() const {
  if (columns < 1)
    throw InputError("contact sheet options", "columns", ">= 1", std::to_string(columns));
  if (tile_width < 16 || tile_width > 4096) {
    throw InputError("contact sheet options", "tile_width", "16..4096",
                     std::to_string(tile_width));
  }
}

ImageU8 MakeContactSheet(const CaptureReader& capture, int frame,
                         const ContactSheetOptions& o) {
  o.Check();
  const int n = capture.num_cameras();
  // Tiles share the largest aspect ratio of the rig.
  double aspect = 0;
  for (const RigCamera& c : capture.rig().cameras()) {
    aspect = std::max(aspect, static_cast<double>(c.camera.height()) / c.camera.width());
  }
  const int tw = o.tile_width;
  const int th = o.crop_to_hand ? tw : static_cast<int>(std::lround(tw * aspect));
  const int cols = std::min(o.columns, n), rows = (n + cols - 1) / cols;
  const int gap = 4;
  ImageU8 sheet(cols * tw + (cols + 1) * gap, rows * th + (rows + 1) * gap, 3, 30);
  const bool has_kp = o.keypoints && capture.Has(kFileKeypoints);
  const std::vector<ViewKeypoints> kps = has_kp || o.crop_to_hand
                                             ? capture.ReadKeypoints(frame)
                                             : std::vector<ViewKeypoints>();
  const bool has_det = o.detections && capture.Has(kFileDetections);
  const std::vector<ViewKeypoints> dets =
      has_det ? capture.ReadDetections(frame) : std::vector<ViewKeypoints>();
  const uint8_t outline[3] = {0, 255, 80};
  for (int c = 0; c < n; ++c) {
    const ImageU8 image = capture.ReadImage(frame, c);
    const bool masked = o.mask_overlay && capture.Has(kFileMask);
    const ImageU8 mask = masked ? capture.ReadMask(frame, c) : ImageU8();
    // Source window: origin (x0, y0) and scale s (tile pixels per image pixel).
    double x0 = -0.5, y0 = -0.5, s = static_cast<double>(tw) / image.width;
    if (o.crop_to_hand) {
      Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        if (kps[c].visibility[k] == 0) continue;
        lo = lo.cwiseMin(kps[c].keypoints.uv_px.row(k).transpose());
        hi = hi.cwiseMax(kps[c].keypoints.uv_px.row(k).transpose());
      }
      if (lo.x() <= hi.x()) {
        const double side = std::max(48.0, 1.6 * (hi - lo).maxCoeff());
        x0 = 0.5 * (lo.x() + hi.x()) - 0.5 * side;
        y0 = 0.5 * (lo.y() + hi.y()) - 0.5 * side;
        s = tw / side;
      } else {
        s = std::min(static_cast<double>(tw) / image.width,
                     static_cast<double>(th) / image.height);
      }
    }
    const int ox = gap + (c % cols) * (tw + gap), oy = gap + (c / cols) * (th + gap);
    // Nearest-neighbour sampling of the window; outside the image stays dark.
    ImageU8 tile(tw, th, 3, 0);
    std::vector<int> src(static_cast<size_t>(tw) * th,
                         -1);  // source pixel per tile pixel
    for (int y = 0; y < th; ++y) {
      for (int x = 0; x < tw; ++x) {
        const int sx = static_cast<int>(std::floor(x0 + (x + 0.5) / s + 0.5));
        const int sy = static_cast<int>(std::floor(y0 + (y + 0.5) / s + 0.5));
        if (!image.Contains(sx, sy)) continue;
        src[y * tw + x] = sy * image.width + sx;
        for (int k = 0; k < 3; ++k) tile.at(x, y, k) = image.at(sx, sy, k);
      }
    }
    if (masked) {  // outline: tile pixels whose mask value differs from a neighbour's
      auto on = [&](int x, int y) {
        const int i = src[y * tw + x];
        return i >= 0 && mask.data[i] != 0;
      };
      for (int y = 1; y + 1 < th; ++y) {
        for (int x = 1; x + 1 < tw; ++x) {
          if (OnMaskOutline(on, x, y)) PutPixel(&tile, x, y, outline);
        }
      }
    }
    auto px = [&](double u) { return (u - x0) * s - 0.5; };
    auto py = [&](double v) { return (v - y0) * s - 0.5; };
    if (has_kp) {
      const ViewKeypoints& v = kps[c];
      for (const auto& bone : kBones) {
        const int a = bone[0], b = bone[1];
        if (v.visibility[a] == 0 || v.visibility[b] == 0) continue;
        DrawLine(&tile, px(v.keypoints.uv_px(a, 0)), py(v.keypoints.uv_px(a, 1)),
                 px(v.keypoints.uv_px(b, 0)), py(v.keypoints.uv_px(b, 1)),
                 kFingerColors[FingerOf(b)]);
      }
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        if (v.visibility[k] == 0) continue;
        DrawDot(&tile, px(v.keypoints.uv_px(k, 0)), py(v.keypoints.uv_px(k, 1)), 3,
                kFingerColors[FingerOf(k)], v.visibility[k] == 2);
      }
    }
    if (has_det) {
      const uint8_t white[3] = {255, 255, 255};
      const ViewKeypoints& d = dets[c];
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        if (!(d.keypoints.confidence[k] > 0)) continue;
        const double x = px(d.keypoints.uv_px(k, 0)), y = py(d.keypoints.uv_px(k, 1));
        DrawLine(&tile, x - 3, y - 3, x + 3, y + 3, white);
        DrawLine(&tile, x - 3, y + 3, x + 3, y - 3, white);
      }
    }
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < tw; ++x)
        for (int k = 0; k < 3; ++k) sheet.at(ox + x, oy + y, k) = tile.at(x, y, k);
  }
  return sheet;
}

}  // namespace handlabel
