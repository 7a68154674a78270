#pragma once
// A small CPU rasteriser for synthetic captures: z-buffered triangles seen through a
// real camera model (distortion included), perspective-correct interpolation, ambient
// + Lambert shading of per-vertex colours or a texture.
//
// How lens distortion is handled exactly: every pixel centre is turned once per camera
// into its undistorted ray (PixelRays, via Camera::NormalizedFromImage). A triangle is
// straight in the normalised image plane (z = 1) of a pinhole, so coverage, depth and
// barycentrics are evaluated there, per pixel, against that pixel's own ray: a pixel is
// covered iff its ray hits the triangle, and its depth is the ray-plane intersection.
// No resampling, no approximation of curved edges. The pixel range searched per
// triangle is the box of its distorted vertices and edge points, padded by 2 pixels;
// this finds every covered pixel for triangles up to ~1/10 of the image (meshes from
// mesh_primitives.h are tessellated to stay far below that).
//
// Conventions: camera axes x right, y down, z forward; depth = z in the camera frame
// (metres); triangles with a vertex closer than `near` are dropped (not clipped).
//
// Two passes: RasterizeMesh() fills the visibility buffer (depth, mesh id, face id,
// barycentrics) for any number of meshes; ShadeVisible() then shades only the visible
// pixels, so overdraw costs no shading and masks are exactly the visible pixels.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/point_arrays.h"
#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "image/image.h"

namespace handlabel {

using MeshColors = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MeshUvs = Eigen::Matrix<float, Eigen::Dynamic, 2, Eigen::RowMajor>;

// A triangle mesh in world coordinates with its surface appearance.
struct RenderMesh {
  Points3d vertices;  // world frame, metres
  Faces faces;        // vertex indices; orientation does not matter (two-sided)
  Points3d normals;   // per vertex; empty = computed from the faces when shading
  MeshColors colors;  // per-vertex albedo in [0, 1]; empty = `color` everywhere
  Eigen::Vector3f color = Eigen::Vector3f(0.8f, 0.8f, 0.8f);
  // Optional texture: albedo = texture(uv) * color, uv in [0, 1] (v down), bilinear,
  // wrapping. Shared and immutable, so meshes copy cheaply.
  MeshUvs uvs;
  std::shared_ptr<const ImageU8> texture;
};

// Area-weighted vertex normals (unit length; zero for unused vertices).
Points3d ComputeVertexNormals(const Points3d& vertices, const Faces& faces);

// The undistorted normalised ray (x, y, 1) of every pixel centre of a camera.
class PixelRays {
 public:
  PixelRays() = default;
  explicit PixelRays(const Camera& camera);
  const Camera& camera() const { return camera_; }
  int width() const { return camera_.width(); }
  int height() const { return camera_.height(); }
  // Normalised coordinates of pixel (x, y): ray = (xy[0], xy[1], 1).
  const double* xy(int x, int y) const {
    return &xy_[2 * (static_cast<size_t>(y) * width() + x)];
  }
  // Box of all pixel rays in the normalised plane (for culling).
  const Eigen::Vector2d& min_xy() const { return min_xy_; }
  const Eigen::Vector2d& max_xy() const { return max_xy_; }

 private:
  Camera camera_;
  std::vector<double> xy_;
  Eigen::Vector2d min_xy_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d max_xy_ = Eigen::Vector2d::Zero();
};

// The PixelRays of the cameras seen so far, shared between threads: a 640 x 480
// camera's rays take 300k undistortions, so pictures of many frames of one rig build them
// once per camera, not once per picture. Holds at most 64 cameras (then starts afresh).
class PixelRaysCache {
 public:
  std::shared_ptr<const PixelRays> Get(const Camera& camera);

 private:
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const PixelRays>> rays_;
};

// Per-pixel result of rasterisation: the nearest surface.
struct VisibilityBuffer {
  int width = 0;
  int height = 0;
  std::vector<float> depth;      // camera z in metres; +inf where nothing was drawn
  std::vector<int16_t> mesh_id;  // caller's id of the visible mesh; -1 = background
  std::vector<int32_t> face_id;  // face of that mesh
  std::vector<float> bary;       // perspective-correct barycentrics b1, b2 (b0 = 1-b1-b2)

  void Reset(int w, int h);
  size_t index(int x, int y) const { return static_cast<size_t>(y) * width + x; }
};

struct RasterizeOptions {
  // Triangles with any vertex at camera z below this (metres) are skipped.
  double near = 0.01;
};

// Draws `mesh` into `buffer` (which must be Reset to the camera's size) with the
// given id (>= 0). Returns the number of faces that were tested (not culled).
int RasterizeMesh(const RenderMesh& mesh, int mesh_id, const Rigid3& cam_from_world,
                  const PixelRays& rays, VisibilityBuffer* buffer,
                  const RasterizeOptions& options = {});

// A directional light: light travels along `direction_in_world` (so surfaces facing
// -direction are lit).
struct DirectionalLight {
  Eigen::Vector3d direction_in_world = Eigen::Vector3d(0, 0, 1);
  Eigen::Vector3f color = Eigen::Vector3f(1, 1, 1);  // intensity per channel
};

struct ShadingOptions {
  Eigen::Vector3f ambient = Eigen::Vector3f(0.35f, 0.35f, 0.35f);  // per channel
  std::vector<DirectionalLight> lights = {DirectionalLight()};
  // Soft (wrap) diffuse per channel: max(0, (n.l + w) / (1 + w)) instead of max(0, n.l),
  // light reaching past the terminator as it does under skin. 0 = Lambert.
  Eigen::Vector3f wrap = Eigen::Vector3f::Zero();
  // Blinn-Phong highlight: specular * light * max(0, n.h)^shininess (0 = none).
  float specular = 0.0f;
  float shininess = 24.0f;
};

// Shades every pixel whose mesh_id >= 0 into `rgb` (3 channels, camera size); pixels of
// the background are left as they are. meshes[id] is the mesh drawn with that id.
// colour = albedo * (ambient + sum_lights color * max(0, n . -direction)), with n
// facing the camera (two-sided), clamped to [0, 255]; with `wrap` or `specular` set,
// the soft diffuse and the highlight of ShadingOptions.
void ShadeVisible(const std::vector<const RenderMesh*>& meshes,
                  const VisibilityBuffer& buffer, const Rigid3& cam_from_world,
                  const PixelRays& rays, const ShadingOptions& options, ImageU8* rgb);

// 255 where the visible mesh is `mesh_id`, else 0.
ImageU8 MaskOfMesh(const VisibilityBuffer& buffer, int mesh_id);

}  // namespace handlabel
