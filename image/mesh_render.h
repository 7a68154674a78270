#pragma once
// A small software rasteriser for pictures of meshes (docs, `handlabel model render`):
// orthographic projection (image/rasterizer.h is the camera-model one for synthetic
// captures), z-buffer, Gouraud-shaded Lambert lighting with per-vertex
// colours. Deterministic: the same mesh and view give the same pixels.

#include <Eigen/Core>
#include <vector>

#include "image/image.h"

namespace handlabel {

struct MeshView {
  // Rows are the image axes in model coordinates: row 0 = image right, row 1 = image
  // down, row 2 = away from the viewer.
  Eigen::Matrix3d view_from_model = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // model point at the image centre
  double pixels_per_metre = 2000.0;
};

// Draws the mesh into `image` (on top of what is there). `colors` has one RGB (0..1)
// per vertex, or is empty for a skin tone. Faces facing away are still drawn (the mesh
// is closed, so the z-buffer hides them).
void DrawMeshOrthographic(const std::vector<Eigen::Vector3d>& vertices,
                          const std::vector<Eigen::Vector3i>& faces,
                          const std::vector<Eigen::Vector3d>& colors,
                          const MeshView& view, ImageU8* image);

// Looking along -y at the palm side or +y at the back etc.: a view whose image axes
// are made from a viewing direction (model coordinates) and an image-up direction.
MeshView LookAlong(const Eigen::Vector3d& direction, const Eigen::Vector3d& up,
                   const Eigen::Vector3d& centre, double pixels_per_metre);

// Copies `tile` into `sheet` with its top-left corner at (x0, y0).
void Paste(const ImageU8& tile, int x0, int y0, ImageU8* sheet);

}  // namespace handlabel
