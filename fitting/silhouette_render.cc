#include "fitting/silhouette_render.h"

#include "core/errors.h"

namespace handlabel {

MaskImage RenderHandMask(const Points3d& vertices, const MeshFaces& faces,
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
