#include "image/mesh_render.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"

namespace handlabel {

MeshView LookAlong(const Eigen::Vector3d& direction, const Eigen::Vector3d& up,
                   const Eigen::Vector3d& centre, double pixels_per_metre) {
  const Eigen::Vector3d forward = direction.normalized();
  const Eigen::Vector3d down = (-up + up.dot(forward) * forward).normalized();
  const Eigen::Vector3d right = down.cross(forward);
  MeshView view;
  view.view_from_model.row(0) = right;
  view.view_from_model.row(1) = down;
  view.view_from_model.row(2) = forward;
  view.centre = centre;
  view.pixels_per_metre = pixels_per_metre;
  return view;
}

void DrawMeshOrthographic(const std::vector<Eigen::Vector3d>& vertices,
                          const std::vector<Eigen::Vector3i>& faces,
                          const std::vector<Eigen::Vector3d>& colors,
                          const MeshView& view, ImageU8* image) {
  HL_CHECK(colors.empty() || colors.size() == vertices.size(), "one colour per vertex");
  const int w = image->width, h = image->height;
  std::vector<double> depth(static_cast<size_t>(w) * h,
                            std::numeric_limits<double>::infinity());
  // Screen positions and per-vertex normals in view coordinates.
  std::vector<Eigen::Vector3d> screen(vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) {
    const Eigen::Vector3d v = view.view_from_model * (vertices[i] - view.centre);
    screen[i] = Eigen::Vector3d(0.5 * (w - 1) + v.x() * view.pixels_per_metre,
                                0.5 * (h - 1) + v.y() * view.pixels_per_metre, v.z());
  }
  std::vector<Eigen::Vector3d> normals(vertices.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : faces) {
    const Eigen::Vector3d n =
        (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]);
    for (int k = 0; k < 3; ++k) normals[f[k]] += n;
  }
  // Light from the viewer's upper left; a little ambient.
  const Eigen::Vector3d light = Eigen::Vector3d(-0.4, -0.5, -1.0).normalized();
  std::vector<Eigen::Vector3d> shade(vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) {
    const Eigen::Vector3d n = (view.view_from_model * normals[i]).normalized();
    const double diffuse = std::max(0.0, n.dot(light));
    const Eigen::Vector3d albedo =
        colors.empty() ? Eigen::Vector3d(0.93, 0.75, 0.63) : colors[i];
    shade[i] = albedo * (0.25 + 0.75 * diffuse);
  }
  for (const Eigen::Vector3i& f : faces) {
    const Eigen::Vector3d& a = screen[f[0]];
    const Eigen::Vector3d& b = screen[f[1]];
    const Eigen::Vector3d& c = screen[f[2]];
    const double area =
        (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (std::abs(area) < 1e-12) continue;
    const int x0 =
        std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int x1 =
        std::min(w - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int y0 =
        std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int y1 =
        std::min(h - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        // Barycentric coordinates of the pixel centre.
        const double l0 = ((b.x() - x) * (c.y() - y) - (b.y() - y) * (c.x() - x)) / area;
        const double l1 = ((c.x() - x) * (a.y() - y) - (c.y() - y) * (a.x() - x)) / area;
        const double l2 = 1.0 - l0 - l1;
        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
        const double z = l0 * a.z() + l1 * b.z() + l2 * c.z();
        double& d = depth[static_cast<size_t>(y) * w + x];
        if (z >= d) continue;
        d = z;
        const Eigen::Vector3d rgb =
            l0 * shade[f[0]] + l1 * shade[f[1]] + l2 * shade[f[2]];
        for (int k = 0; k < 3; ++k) {
          image->at(x, y, k) =
              static_cast<uint8_t>(std::clamp(rgb[k], 0.0, 1.0) * 255.0 + 0.5);
        }
      }
    }
  }
}

void Paste(const ImageU8& tile, int x0, int y0, ImageU8* sheet) {
  for (int y = 0; y < tile.height; ++y) {
    for (int x = 0; x < tile.width; ++x) {
      if (x0 + x < 0 || y0 + y < 0 || x0 + x >= sheet->width || y0 + y >= sheet->height)
        continue;
      for (int k = 0; k < 3; ++k) sheet->at(x0 + x, y0 + y, k) = tile.at(x, y, k);
    }
  }
}

}  // namespace handlabel
