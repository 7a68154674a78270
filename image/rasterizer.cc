#include "image/rasterizer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"

namespace handlabel {

Points3d ComputeVertexNormals(const Points3d& vertices, const Faces& faces) {
  Points3d normals = Points3d::Zero(vertices.rows(), 3);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector3d a = vertices.row(faces(f, 0));
    const Eigen::Vector3d b = vertices.row(faces(f, 1));
    const Eigen::Vector3d c = vertices.row(faces(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();  // length = 2 area
    for (int k = 0; k < 3; ++k) normals.row(faces(f, k)) += n;
  }
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    const double len = normals.row(v).norm();
    if (len > 0) normals.row(v) /= len;
  }
  return normals;
}

PixelRays::PixelRays(const Camera& camera) : camera_(camera) {
  const int w = camera.width(), h = camera.height();
  xy_.resize(2 * static_cast<size_t>(w) * h);
  min_xy_.setConstant(std::numeric_limits<double>::infinity());
  max_xy_.setConstant(-std::numeric_limits<double>::infinity());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2d n = camera.NormalizedFromImage(Eigen::Vector2d(x, y));
      double* out = &xy_[2 * (static_cast<size_t>(y) * w + x)];
      out[0] = n.x();
      out[1] = n.y();
      min_xy_ = min_xy_.cwiseMin(n);
      max_xy_ = max_xy_.cwiseMax(n);
    }
  }
}

std::shared_ptr<const PixelRays> PixelRaysCache::Get(const Camera& camera) {
  // The key is everything the rays depend on: model, size and the exact parameters.
  std::string key = std::to_string(static_cast<int>(camera.model())) + " " +
                    std::to_string(camera.width()) + "x" +
                    std::to_string(camera.height());
  key.append(reinterpret_cast<const char*>(camera.params().data()),
             camera.params().size() * sizeof(double));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = rays_.find(key);
    if (it != rays_.end()) return it->second;
  }
  auto rays = std::make_shared<const PixelRays>(camera);  // built outside the lock
  std::lock_guard<std::mutex> lock(mutex_);
  if (rays_.size() >= 64) rays_.clear();
  return rays_.emplace(key, std::move(rays)).first->second;
}

void VisibilityBuffer::Reset(int w, int h) {
  width = w;
  height = h;
  const size_t n = static_cast<size_t>(w) * h;
  depth.assign(n, std::numeric_limits<float>::infinity());
  mesh_id.assign(n, -1);
  face_id.assign(n, -1);
  bary.assign(2 * n, 0.0f);
}

namespace {

// Twice the signed area of (a, b, p).
inline double Edge(double ax, double ay, double bx, double by, double px, double py) {
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

// Edge function with the endpoints in a canonical order, so that the two triangles
// sharing an edge compute bitwise-opposite values: a pixel on a shared edge is never
// rejected by both (no cracks between triangles).
inline double CanonicalEdge(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double px,
                            double py) {
  if (a.x() < b.x() || (a.x() == b.x() && a.y() < b.y())) {
    return Edge(a.x(), a.y(), b.x(), b.y(), px, py);
  }
  return -Edge(b.x(), b.y(), a.x(), a.y(), px, py);
}

// Per vertex: camera point, normalised coordinates and pixel (distorted) position;
// q and uv are left unset for vertices before the near plane.
struct ProjectedVertices {
  std::vector<Eigen::Vector3d> pc;
  std::vector<Eigen::Vector2d> q, uv;
};

ProjectedVertices ProjectVertices(const RenderMesh& mesh, const Rigid3& cam_from_world,
                                  const Camera& camera, double near) {
  const Eigen::Index nv = mesh.vertices.rows();
  const Eigen::Matrix3d r = cam_from_world.rotation.toRotationMatrix();
  const Eigen::Vector3d& t = cam_from_world.translation;
  ProjectedVertices p;
  p.pc.resize(nv);
  p.q.resize(nv);
  p.uv.resize(nv);
  for (Eigen::Index v = 0; v < nv; ++v) {
    p.pc[v] = r * mesh.vertices.row(v).transpose() + t;
    if (p.pc[v].z() < near) continue;
    p.q[v] = p.pc[v].head<2>() / p.pc[v].z();
    p.uv[v] = camera.ImageFromNormalized(p.q[v]);
  }
  return p;
}

// Inclusive pixel range that a face may cover.
struct PixelBox {
  int x0, y0, x1, y1;
};

// The face's pixel search box, clipped to the image (empty: x0 > x1 or y0 > y1).
// With distortion, edges are curved in the image and a face far outside the image's
// rays cannot be trusted to project sensibly: search the whole image then.
PixelBox FacePixelBox(const PixelRays& rays, const ProjectedVertices& p, int i0, int i1,
                      int i2, const Eigen::Vector2d& qmin, const Eigen::Vector2d& qmax) {
  const Camera& camera = rays.camera();
  const bool distorted = camera.HasDistortion();
  const int w = rays.width(), h = rays.height();
  // The normalised-plane box where the distorted projection is still trustworthy:
  // the image's ray box with a generous margin (distortion polynomials can fold back
  // far outside the image).
  const Eigen::Vector2d span = rays.max_xy() - rays.min_xy();
  const Eigen::Vector2d valid_min = rays.min_xy() - 0.25 * span;
  const Eigen::Vector2d valid_max = rays.max_xy() + 0.25 * span;
  double umin, umax, vmin, vmax;
  const bool trust = !distorted || ((qmin.array() >= valid_min.array()).all() &&
                                    (qmax.array() <= valid_max.array()).all());
  if (!trust) {
    umin = vmin = -1;
    umax = w;
    vmax = h;
  } else {
    Eigen::Vector2d lo = p.uv[i0].cwiseMin(p.uv[i1]).cwiseMin(p.uv[i2]);
    Eigen::Vector2d hi = p.uv[i0].cwiseMax(p.uv[i1]).cwiseMax(p.uv[i2]);
    if (distorted) {  // edges are curved in the image: add points along them
      const Eigen::Vector2d* corners[3] = {&p.q[i0], &p.q[i1], &p.q[i2]};
      for (int e = 0; e < 3; ++e) {
        const Eigen::Vector2d& a = *corners[e];
        const Eigen::Vector2d& b = *corners[(e + 1) % 3];
        for (double s : {0.25, 0.5, 0.75}) {
          const Eigen::Vector2d pt = camera.ImageFromNormalized(a + s * (b - a));
          lo = lo.cwiseMin(pt);
          hi = hi.cwiseMax(pt);
        }
      }
    }
    const double pad = distorted ? 2.0 : 1.0;
    umin = lo.x() - pad;
    vmin = lo.y() - pad;
    umax = hi.x() + pad;
    vmax = hi.y() + pad;
  }
  return {std::max(0, static_cast<int>(std::ceil(umin))),
          std::max(0, static_cast<int>(std::ceil(vmin))),
          std::min(w - 1, static_cast<int>(std::floor(umax))),
          std::min(h - 1, static_cast<int>(std::floor(vmax)))};
}

// Depth-tests and writes the pixels of `box` inside face f (vertices i0, i1, i2 with
// normalised-plane signed area `area`).
void DrawFace(const PixelRays& rays, const ProjectedVertices& p, int i0, int i1, int i2,
              double area, const PixelBox& box, int mesh_id, Eigen::Index f,
              VisibilityBuffer* buffer) {
  const Eigen::Vector2d& q0 = p.q[i0];
  const Eigen::Vector2d& q1 = p.q[i1];
  const Eigen::Vector2d& q2 = p.q[i2];
  float* depth = buffer->depth.data();
  const double inv_area = 1.0 / area;
  const double iz0 = 1.0 / p.pc[i0].z(), iz1 = 1.0 / p.pc[i1].z(),
               iz2 = 1.0 / p.pc[i2].z();
  for (int y = box.y0; y <= box.y1; ++y) {
    for (int x = box.x0; x <= box.x1; ++x) {
      const double* ray = rays.xy(x, y);
      // Screen-space barycentrics in the normalised plane (same sign as area
      // inside the triangle, whatever its orientation).
      double l0 = CanonicalEdge(q1, q2, ray[0], ray[1]) * inv_area;
      double l1 = CanonicalEdge(q2, q0, ray[0], ray[1]) * inv_area;
      double l2 = CanonicalEdge(q0, q1, ray[0], ray[1]) * inv_area;
      if (l0 < 0 || l1 < 0 || l2 < 0) continue;
      const double sum = l0 + l1 + l2;  // 1 up to rounding
      l0 /= sum;
      l1 /= sum;
      l2 /= sum;
      // 1/z is affine along the plane's image: exact ray-plane depth.
      const double inv_z = l0 * iz0 + l1 * iz1 + l2 * iz2;
      const double z = 1.0 / inv_z;
      const size_t idx = buffer->index(x, y);
      if (!(z < depth[idx])) continue;
      depth[idx] = static_cast<float>(z);
      buffer->mesh_id[idx] = static_cast<int16_t>(mesh_id);
      buffer->face_id[idx] = static_cast<int32_t>(f);
      buffer->bary[2 * idx] = static_cast<float>(l1 * iz1 * z);
      buffer->bary[2 * idx + 1] = static_cast<float>(l2 * iz2 * z);
    }
  }
}

}  // namespace

int RasterizeMesh(const RenderMesh& mesh, int mesh_id, const Rigid3& cam_from_world,
                  const PixelRays& rays, VisibilityBuffer* buffer,
                  const RasterizeOptions& options) {
  HL_CHECK(mesh_id >= 0 && mesh_id < 32768, "mesh id out of range");
  HL_CHECK(buffer->width == rays.width() && buffer->height == rays.height(),
           "visibility buffer not reset to the camera size");
  const ProjectedVertices p =
      ProjectVertices(mesh, cam_from_world, rays.camera(), options.near);
  int tested = 0;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    const int i0 = mesh.faces(f, 0), i1 = mesh.faces(f, 1), i2 = mesh.faces(f, 2);
    if (p.pc[i0].z() < options.near || p.pc[i1].z() < options.near ||
        p.pc[i2].z() < options.near) {
      continue;
    }
    const Eigen::Vector2d& q0 = p.q[i0];
    const Eigen::Vector2d& q1 = p.q[i1];
    const Eigen::Vector2d& q2 = p.q[i2];
    const Eigen::Vector2d qmin = q0.cwiseMin(q1).cwiseMin(q2);
    const Eigen::Vector2d qmax = q0.cwiseMax(q1).cwiseMax(q2);
    // Entirely outside the image's rays: nothing to draw.
    if ((qmax.array() < rays.min_xy().array()).any() ||
        (qmin.array() > rays.max_xy().array()).any()) {
      continue;
    }
    const double area = Edge(q0.x(), q0.y(), q1.x(), q1.y(), q2.x(), q2.y());
    if (std::abs(area) < 1e-18) continue;  // degenerate or seen edge-on
    ++tested;
    const PixelBox box = FacePixelBox(rays, p, i0, i1, i2, qmin, qmax);
    if (box.x0 > box.x1 || box.y0 > box.y1) continue;
    DrawFace(rays, p, i0, i1, i2, area, box, mesh_id, f, buffer);
  }
  return tested;
}

namespace {

Eigen::Vector3f SampleTexture(const ImageU8& tex, float u, float v) {
  const float fx = (u - std::floor(u)) * tex.width - 0.5f;
  const float fy = (v - std::floor(v)) * tex.height - 0.5f;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const float ax = fx - x0, ay = fy - y0;
  Eigen::Vector3f out = Eigen::Vector3f::Zero();
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const int x = ((x0 + dx) % tex.width + tex.width) % tex.width;
      const int y = ((y0 + dy) % tex.height + tex.height) % tex.height;
      const float wgt = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
      for (int c = 0; c < 3; ++c) {
        out[c] += wgt * tex.at(x, y, std::min(c, tex.channels - 1)) / 255.0f;
      }
    }
  }
  return out;
}

}  // namespace

void ShadeVisible(const std::vector<const RenderMesh*>& meshes,
                  const VisibilityBuffer& buffer, const Rigid3& cam_from_world,
                  const PixelRays& rays, const ShadingOptions& options, ImageU8* rgb) {
  HL_CHECK(
      rgb->width == buffer.width && rgb->height == buffer.height && rgb->channels == 3,
      "rgb image must be 3 channels of the camera size");
  // Normals of meshes that have none, computed once per call.
  std::vector<Points3d> own_normals(meshes.size());
  std::vector<const Points3d*> normals(meshes.size());
  for (size_t m = 0; m < meshes.size(); ++m) {
    if (meshes[m] == nullptr) continue;
    if (meshes[m]->normals.rows() == meshes[m]->vertices.rows()) {
      normals[m] = &meshes[m]->normals;
    } else {
      own_normals[m] = ComputeVertexNormals(meshes[m]->vertices, meshes[m]->faces);
      normals[m] = &own_normals[m];
    }
  }
  // Lights in the camera frame, pointing towards the light.
  const Eigen::Matrix3d r = cam_from_world.rotation.toRotationMatrix();
  std::vector<Eigen::Vector3f> to_light;
  for (const DirectionalLight& l : options.lights) {
    to_light.push_back((-(r * l.direction_in_world.normalized())).cast<float>());
  }
  const Eigen::Matrix3f rf = r.cast<float>();
  const bool soft = !options.wrap.isZero() || options.specular > 0;
  for (int y = 0; y < buffer.height; ++y) {
    for (int x = 0; x < buffer.width; ++x) {
      const size_t idx = buffer.index(x, y);
      const int m = buffer.mesh_id[idx];
      if (m < 0) continue;
      HL_CHECK(m < static_cast<int>(meshes.size()) && meshes[m] != nullptr,
               "visible mesh id without a mesh");
      const RenderMesh& mesh = *meshes[m];
      const int f = buffer.face_id[idx];
      const float b1 = buffer.bary[2 * idx], b2 = buffer.bary[2 * idx + 1];
      const float b0 = 1.0f - b1 - b2;
      const int v0 = mesh.faces(f, 0), v1 = mesh.faces(f, 1), v2 = mesh.faces(f, 2);
      const Points3d& nm = *normals[m];
      Eigen::Vector3f n =
          rf *
          (b0 * nm.row(v0) + b1 * nm.row(v1) + b2 * nm.row(v2)).transpose().cast<float>();
      const double* ray = rays.xy(x, y);
      // Two-sided: the normal faces the camera.
      if (n.x() * ray[0] + n.y() * ray[1] + n.z() > 0) n = -n;
      const float len = n.norm();
      if (len > 0) n /= len;
      Eigen::Vector3f albedo = mesh.color;
      if (mesh.colors.rows() == mesh.vertices.rows()) {
        albedo = (b0 * mesh.colors.row(v0) + b1 * mesh.colors.row(v1) +
                  b2 * mesh.colors.row(v2))
                     .transpose();
      }
      if (mesh.texture != nullptr && mesh.uvs.rows() == mesh.vertices.rows()) {
        const Eigen::Vector2f uv =
            (b0 * mesh.uvs.row(v0) + b1 * mesh.uvs.row(v1) + b2 * mesh.uvs.row(v2))
                .transpose();
        albedo = albedo.cwiseProduct(SampleTexture(*mesh.texture, uv.x(), uv.y()));
      }
      Eigen::Vector3f light = options.ambient;
      Eigen::Vector3f highlight = Eigen::Vector3f::Zero();
      if (soft) {
        const Eigen::Vector3f to_eye =
            -Eigen::Vector3f(static_cast<float>(ray[0]), static_cast<float>(ray[1]), 1.0f)
                 .normalized();
        for (size_t l = 0; l < to_light.size(); ++l) {
          const float d = n.dot(to_light[l]);
          for (int c = 0; c < 3; ++c) {
            const float w = options.wrap[c];
            light[c] += options.lights[l].color[c] * std::max(0.0f, (d + w) / (1 + w));
          }
          const float nh = std::max(0.0f, n.dot((to_light[l] + to_eye).normalized()));
          if (d > 0)
            highlight += options.lights[l].color * std::pow(nh, options.shininess);
        }
        highlight *= options.specular;
      } else {
        for (size_t l = 0; l < to_light.size(); ++l) {
          light += options.lights[l].color * std::max(0.0f, n.dot(to_light[l]));
        }
      }
      for (int c = 0; c < 3; ++c) {
        // (The Lambert-only form keeps its original evaluation order: same bytes.)
        const float value = soft ? 255.0f * (albedo[c] * light[c] + highlight[c])
                                 : 255.0f * albedo[c] * light[c];
        rgb->at(x, y, c) = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
      }
    }
  }
}

ImageU8 MaskOfMesh(const VisibilityBuffer& buffer, int mesh_id) {
  ImageU8 mask(buffer.width, buffer.height, 1);
  for (size_t i = 0; i < buffer.mesh_id.size(); ++i) {
    if (buffer.mesh_id[i] == mesh_id) mask.data[i] = 255;
  }
  return mask;
}

}  // namespace handlabel
