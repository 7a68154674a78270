#include "pipeline/fit_overlay.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "fitting/silhouette_render.h"

namespace handlabel {
namespace {

// SNAP skeleton: parent of each keypoint (wrist = -1).
constexpr int kSnapParent[kNumHandKeypoints] = {-1, 0,  1, 2,  3,  0,  5, 6,  7,  0, 9,
                                                10, 11, 0, 13, 14, 15, 0, 17, 18, 19};

void Put(ImageU8* img, int x, int y, const uint8_t rgb[3]) {
  if (!img->Contains(x, y)) return;
  for (int c = 0; c < 3; ++c) img->at(x, y, c) = rgb[c];
}

void Line(ImageU8* img, Eigen::Vector2d a, Eigen::Vector2d b, const uint8_t rgb[3]) {
  const int steps = static_cast<int>(std::ceil((b - a).norm())) + 1;
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2d p = a + (b - a) * (double(i) / steps);
    Put(img, static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y())),
        rgb);
  }
}

}  // namespace

ImageU8 MakeFitOverlay(const std::vector<ImageU8>& images,
                       const std::vector<KeypointView>& views,
                       const std::vector<PixelRays>& rays, const Points3d& vertices,
                       const MeshFaces& faces, const Points3d& keypoints,
                       const FitOverlayOptions& options) {
  HL_CHECK(images.size() == views.size() && rays.size() == views.size(),
           "one image and one set of rays per view");
  HL_CHECK(options.columns >= 1 && options.tile_width >= 16, "overlay layout");
  if (views.empty()) return ImageU8(1, 1, 3);
  // Square tiles, each cropped around the fitted hand in its view.
  const int tw = options.tile_width;
  const int th = tw;
  const int cols = std::min<int>(options.columns, static_cast<int>(views.size()));
  const int rows = (static_cast<int>(views.size()) + cols - 1) / cols;
  ImageU8 sheet(cols * tw, rows * th, 3, 0);
  const uint8_t green[3] = {40, 230, 60}, red[3] = {240, 40, 40};
  for (size_t v = 0; v < views.size(); ++v) {
    const ImageU8& img = images[v];
    const MaskImage mask = RenderHandMask(vertices, faces, views[v].camera, rays[v]);
    Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      Eigen::Vector2d uv;
      if (!views[v].camera.ProjectWorld(keypoints.row(k).transpose(), &uv)) continue;
      lo = lo.cwiseMin(uv);
      hi = hi.cwiseMax(uv);
    }
    if (lo.x() > hi.x()) {  // hand behind the camera: the whole image
      lo = Eigen::Vector2d(0, 0);
      hi = Eigen::Vector2d(img.width, img.height);
    }
    const double side = std::max(40.0, 1.5 * (hi - lo).maxCoeff());
    const Eigen::Vector2d origin = 0.5 * (lo + hi) - Eigen::Vector2d(side, side) / 2;
    const double scale = side / tw;
    ImageU8 tile(tw, th, 3, 0);
    for (int y = 0; y < th; ++y) {
      for (int x = 0; x < tw; ++x) {
        const int sx = static_cast<int>(std::floor(origin.x() + x * scale));
        const int sy = static_cast<int>(std::floor(origin.y() + y * scale));
        if (sx < 0 || sy < 0 || sx >= img.width || sy >= img.height) continue;
        for (int c = 0; c < 3; ++c) {
          const double value = img.at(sx, sy, img.channels == 1 ? 0 : c);
          tile.at(x, y, c) =
              static_cast<uint8_t>(mask(sy, sx) ? 0.55 * value + 0.45 * green[c] : value);
        }
      }
    }
    auto to_tile = [&](const Eigen::Vector2d& uv) {
      return Eigen::Vector2d((uv - origin) / scale);
    };
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!(views[v].keypoints.confidence[k] > 0.0)) continue;
      const Eigen::Vector2d p = to_tile(views[v].keypoints.uv_px.row(k).transpose());
      for (int d = -2; d <= 2; ++d) {
        Put(&tile, static_cast<int>(p.x()) + d, static_cast<int>(p.y()) + d, red);
        Put(&tile, static_cast<int>(p.x()) + d, static_cast<int>(p.y()) - d, red);
      }
    }
    std::vector<Eigen::Vector2d> uv(kNumHandKeypoints);
    std::vector<bool> ok(kNumHandKeypoints);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      ok[k] = views[v].camera.ProjectWorld(keypoints.row(k).transpose(), &uv[k]);
      uv[k] = to_tile(uv[k]);
    }
    for (int k = 1; k < kNumHandKeypoints; ++k) {
      if (ok[k] && ok[kSnapParent[k]]) Line(&tile, uv[kSnapParent[k]], uv[k], green);
    }
    const int ox = static_cast<int>(v % cols) * tw, oy = static_cast<int>(v / cols) * th;
    for (int y = 0; y < th; ++y) {
      for (int x = 0; x < tw; ++x) {
        for (int c = 0; c < 3; ++c) sheet.at(ox + x, oy + y, c) = tile.at(x, y, c);
      }
    }
  }
  return sheet;
}

}  // namespace handlabel
