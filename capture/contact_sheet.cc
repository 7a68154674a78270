#include "capture/contact_sheet.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"
#include "hand/hand_skeleton.h"
#include "image/draw.h"
#include "image/mask_outline.h"
#include "image/mesh_render.h"

namespace handlabel {
namespace {

constexpr int kGap = 4;  // pixels between tiles and around the sheet

// The part of a view a tile shows: tile pixel (x, y) samples image point
// (x0 + (x + 0.5) / scale, y0 + (y + 0.5) / scale); scale is tile pixels per image pixel.
struct TileWindow {
  double x0 = -0.5, y0 = -0.5, scale = 1;
  Eigen::Vector2d ToTile(double u, double v) const {
    return Eigen::Vector2d((u - x0) * scale - 0.5, (v - y0) * scale - 0.5);
  }
};

// The whole view scaled to the tile width, or with crop_to_hand a square around the
// in-frame keypoints (the whole view, fitted into the tile, when none is in frame).
TileWindow ChooseWindow(const ImageU8& image, const ViewKeypoints* keypoints, int tw,
                        int th) {
  TileWindow w;
  w.scale = static_cast<double>(tw) / image.width;
  if (keypoints == nullptr) return w;
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (keypoints->visibility[k] == 0) continue;
    lo = lo.cwiseMin(keypoints->keypoints.uv_px.row(k).transpose());
    hi = hi.cwiseMax(keypoints->keypoints.uv_px.row(k).transpose());
  }
  if (lo.x() <= hi.x()) {
    const double side = std::max(48.0, 1.6 * (hi - lo).maxCoeff());
    w.x0 = 0.5 * (lo.x() + hi.x()) - 0.5 * side;
    w.y0 = 0.5 * (lo.y() + hi.y()) - 0.5 * side;
    w.scale = tw / side;
  } else {
    w.scale = std::min(static_cast<double>(tw) / image.width,
                       static_cast<double>(th) / image.height);
  }
  return w;
}

// Nearest-neighbour sampling of the window; outside the image stays dark. `source`
// gets the image pixel index per tile pixel (-1 outside).
ImageU8 SampleTile(const ImageU8& image, const TileWindow& w, int tw, int th,
                   std::vector<int>* source) {
  ImageU8 tile(tw, th, 3, 0);
  source->assign(static_cast<size_t>(tw) * th, -1);
  for (int y = 0; y < th; ++y) {
    for (int x = 0; x < tw; ++x) {
      const int sx = static_cast<int>(std::floor(w.x0 + (x + 0.5) / w.scale + 0.5));
      const int sy = static_cast<int>(std::floor(w.y0 + (y + 0.5) / w.scale + 0.5));
      if (!image.Contains(sx, sy)) continue;
      (*source)[y * tw + x] = sy * image.width + sx;
      for (int k = 0; k < 3; ++k) tile.at(x, y, k) = image.at(sx, sy, k);
    }
  }
  return tile;
}

// Paints tile pixels whose mask value differs from a neighbour's.
void DrawMaskOutline(const ImageU8& mask, const std::vector<int>& source, ImageU8* tile) {
  const Rgb outline = {0, 255, 80};
  auto on = [&](int x, int y) {
    const int i = source[y * tile->width + x];
    return i >= 0 && mask.data[i] != 0;
  };
  for (int y = 1; y + 1 < tile->height; ++y) {
    for (int x = 1; x + 1 < tile->width; ++x) {
      if (OnMaskOutline(on, x, y)) SetPixel(tile, x, y, outline);
    }
  }
}

// The sheets' line: one sample more than DrawLine's when the extent is a whole number
// of pixels (kept so that sheets stay as they were).
void SheetLine(ImageU8* tile, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
               const Rgb& color) {
  const double extent = std::max(std::abs(b.x() - a.x()), std::abs(b.y() - a.y()));
  DrawLineSamples(tile, a, b, static_cast<int>(extent) + 1, color);
}

// Skeleton, then keypoints: visible filled, occluded hollow, out of frame left out.
void DrawKeypoints(const ViewKeypoints& v, const TileWindow& w, ImageU8* tile) {
  auto at = [&](int k) {
    return w.ToTile(v.keypoints.uv_px(k, 0), v.keypoints.uv_px(k, 1));
  };
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    const int parent = kSnapParents[k];
    if (v.visibility[parent] == 0 || v.visibility[k] == 0) continue;
    SheetLine(tile, at(parent), at(k), SnapKeypointColor(k));
  }
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (v.visibility[k] == 0) continue;
    if (v.visibility[k] == 2) {
      DrawDisc(tile, at(k), 3, SnapKeypointColor(k));
    } else {
      DrawRing(tile, at(k), 3, SnapKeypointColor(k));
    }
  }
}

// A white cross per detected keypoint.
void DrawDetections(const ViewKeypoints& d, const TileWindow& w, ImageU8* tile) {
  const Rgb white = {255, 255, 255};
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (!(d.keypoints.confidence[k] > 0)) continue;
    const Eigen::Vector2d p = w.ToTile(d.keypoints.uv_px(k, 0), d.keypoints.uv_px(k, 1));
    SheetLine(tile, p + Eigen::Vector2d(-3, -3), p + Eigen::Vector2d(3, 3), white);
    SheetLine(tile, p + Eigen::Vector2d(-3, 3), p + Eigen::Vector2d(3, -3), white);
  }
}

}  // namespace

void ContactSheetOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "columns", columns, 1);
  RequireInRange(source, "tile_width", tile_width, 16, 4096);
}

ImageU8 MakeContactSheet(const CaptureReader& capture, int frame,
                         const ContactSheetOptions& o) {
  o.Check("contact sheet options");
  const int n = capture.num_cameras();
  // Tiles share the largest aspect ratio of the rig.
  double aspect = 0;
  for (const RigCamera& c : capture.rig().cameras()) {
    aspect = std::max(aspect, static_cast<double>(c.camera.height()) / c.camera.width());
  }
  const int tw = o.tile_width;
  const int th = o.crop_to_hand ? tw : static_cast<int>(std::lround(tw * aspect));
  const int cols = std::min(o.columns, n), rows = (n + cols - 1) / cols;
  ImageU8 sheet(cols * tw + (cols + 1) * kGap, rows * th + (rows + 1) * kGap, 3, 30);
  const bool has_kp = o.keypoints && capture.Has(kFileKeypoints);
  const std::vector<ViewKeypoints> kps = has_kp || o.crop_to_hand
                                             ? capture.ReadKeypoints(frame)
                                             : std::vector<ViewKeypoints>();
  const bool has_det = o.detections && capture.Has(kFileDetections);
  const std::vector<ViewKeypoints> dets =
      has_det ? capture.ReadDetections(frame) : std::vector<ViewKeypoints>();
  const bool masked = o.mask_overlay && capture.Has(kFileMask);
  for (int c = 0; c < n; ++c) {
    const ImageU8 image = capture.ReadImage(frame, c);
    const TileWindow window =
        ChooseWindow(image, o.crop_to_hand ? &kps[c] : nullptr, tw, th);
    std::vector<int> source;
    ImageU8 tile = SampleTile(image, window, tw, th, &source);
    if (masked) DrawMaskOutline(capture.ReadMask(frame, c), source, &tile);
    if (has_kp) DrawKeypoints(kps[c], window, &tile);
    if (has_det) DrawDetections(dets[c], window, &tile);
    Paste(tile, kGap + (c % cols) * (tw + kGap), kGap + (c / cols) * (th + kGap), &sheet);
  }
  return sheet;
}

}  // namespace handlabel
