#include "fitting/silhouette_render.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/errors.h"

namespace handlabel {
namespace {

// Twice the signed area of (a, b, p): which side of a -> b the point p lies on.
double EdgeSide(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double x, double y) {
  return (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
}

// Marks the pixels of `covered` (a window at `origin`) whose centre lies in the
// triangle (either orientation; on an edge counts).
void FillTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                  const Eigen::Vector2d& c, const Eigen::Vector2i& origin,
                  MaskImage* covered) {
  const double area = EdgeSide(a, b, c.x(), c.y());
  if (area == 0.0) return;
  const double sign = area > 0 ? 1.0 : -1.0;
  const int x0 =
      std::max(static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))), origin.x());
  const int y0 =
      std::max(static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))), origin.y());
  const int x1 = std::min(static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))),
                          origin.x() + static_cast<int>(covered->cols()) - 1);
  const int y1 = std::min(static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))),
                          origin.y() + static_cast<int>(covered->rows()) - 1);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      if (sign * EdgeSide(a, b, x, y) >= 0 && sign * EdgeSide(b, c, x, y) >= 0 &&
          sign * EdgeSide(c, a, x, y) >= 0) {
        (*covered)(y - origin.y(), x - origin.x()) = 1;
      }
    }
  }
}

}  // namespace

double ProjectedMeshIoU(const Points3d& vertices, const Faces& faces,
                        const RigCamera& camera, const MaskImage& mask,
                        const MaskImage* ignore) {
  const int w = camera.camera.width(), h = camera.camera.height();
  HL_CHECK(mask.rows() == h && mask.cols() == w, "mask of the camera's size");
  HL_CHECK(!ignore || ignore->size() == mask.size(), "ignore mask differs in size");
  std::vector<Eigen::Vector2d> uv(vertices.rows());
  std::vector<char> seen(vertices.rows());
  Eigen::Vector2d lo(w, h), hi(-1, -1);
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    seen[i] = camera.ProjectWorld(vertices.row(i).transpose(), &uv[i]) &&
              uv[i].cwiseAbs().maxCoeff() < 1e6;
    if (!seen[i]) continue;
    lo = lo.cwiseMin(uv[i]);
    hi = hi.cwiseMax(uv[i]);
  }
  // The window: the projected mesh's box within the image.
  const Eigen::Vector2i origin(std::max(0, static_cast<int>(std::ceil(lo.x()))),
                               std::max(0, static_cast<int>(std::ceil(lo.y()))));
  const int x1 = std::min(w - 1, static_cast<int>(std::floor(hi.x())));
  const int y1 = std::min(h - 1, static_cast<int>(std::floor(hi.y())));
  MaskImage covered =
      MaskImage::Zero(std::max(0, y1 - origin.y() + 1), std::max(0, x1 - origin.x() + 1));
  if (covered.size() > 0) {
    for (Eigen::Index f = 0; f < faces.rows(); ++f) {
      const int i0 = faces(f, 0), i1 = faces(f, 1), i2 = faces(f, 2);
      if (!seen[i0] || !seen[i1] || !seen[i2]) continue;
      FillTriangle(uv[i0], uv[i1], uv[i2], origin, &covered);
    }
  }
  auto counts = [&](int x, int y) { return !ignore || (*ignore)(y, x) == 0; };
  // Whole-image counts as array expressions: no per-pixel branch (this ran on every
  // view of every fit stage).
  long in_mask = ignore ? ((mask.array() != 0) && (ignore->array() == 0)).count()
                        : (mask.array() != 0).count();
  long both = 0, in_mesh = 0;
  for (int y = 0; y < covered.rows(); ++y) {
    for (int x = 0; x < covered.cols(); ++x) {
      const int u = x + origin.x(), v = y + origin.y();
      if (covered(y, x) == 0 || !counts(u, v)) continue;
      ++in_mesh;
      both += mask(v, u) != 0;
    }
  }
  const long either = in_mask + in_mesh - both;
  return either == 0 ? 1.0 : double(both) / double(either);
}

MaskImage RenderHandMask(const Points3d& vertices, const Faces& faces,
                         const RigCamera& camera, const PixelRays& rays) {
  RenderMesh mesh;
  mesh.vertices = vertices;
  mesh.faces = faces;
  VisibilityBuffer buffer;
  buffer.Reset(rays.width(), rays.height());
  RasterizeMesh(mesh, 0, camera.cam_from_world, rays, &buffer);
  MaskImage mask(rays.height(), rays.width());
  for (int y = 0; y < rays.height(); ++y) {
    for (int x = 0; x < rays.width(); ++x) {
      mask(y, x) = buffer.mesh_id[buffer.index(x, y)] == 0 ? 1 : 0;
    }
  }
  return mask;
}

double MaskIoU(const MaskImage& a, const MaskImage& b, const MaskImage* ignore) {
  HL_CHECK(a.rows() == b.rows() && a.cols() == b.cols(), "masks differ in size");
  HL_CHECK(!ignore || ignore->size() == a.size(), "ignore mask differs in size");
  long both = 0, either = 0;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (ignore && ignore->data()[i] != 0) continue;
    const bool x = a.data()[i] != 0, y = b.data()[i] != 0;
    both += x && y;
    either += x || y;
  }
  return either == 0 ? 1.0 : double(both) / double(either);
}

}  // namespace handlabel
