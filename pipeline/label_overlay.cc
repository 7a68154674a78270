#include "pipeline/label_overlay.h"

#include <cmath>

#include "core/image_file.h"
#include "core/rasterizer.h"
#include "core/atomic_file.h"
#include "pipeline/label_outputs.h"

namespace handlabel {
namespace {

// SNAP parent of each keypoint (-1: wrist) and finger of each keypoint (0 = wrist).
constexpr int kSnapParent[kNumHandKeypoints] = {-1, 0,  1, 2,  3,  0,  5, 6,  7,  0, 9,
                                                10, 11, 0, 13, 14, 15, 0, 17, 18, 19};
const uint8_t kFingerColor[6][3] = {{255, 255, 255}, {255, 80, 80},  {255, 200, 40},
                                    {80, 220, 80},   {60, 160, 255}, {220, 90, 255}};

int Finger(int k) { return k == 0 ? 0 : 1 + (k - 1) / 4; }

void PutPixel(int x, int y, const uint8_t* color, ImageU8* rgb) {
  if (!rgb->Contains(x, y)) return;
  for (int c = 0; c < 3; ++c) rgb->at(x, y, c) = color[c];
}

void DrawDisc(const Eigen::Vector2d& center, double radius, const uint8_t* color,
              ImageU8* rgb) {
  const int r = static_cast<int>(std::ceil(radius));
  const int cx = static_cast<int>(std::lround(center.x()));
  const int cy = static_cast<int>(std::lround(center.y()));
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      if (dx * dx + dy * dy <= radius * radius) PutPixel(cx + dx, cy + dy, color, rgb);
    }
  }
}

void DrawLine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double width,
              const uint8_t* color, ImageU8* rgb) {
  const double length = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(length)));
  if (steps > 4 * (rgb->width + rgb->height)) return;  // far outside: skip
  for (int i = 0; i <= steps; ++i) {
    DrawDisc(a + (b - a) * (double(i) / steps), width / 2, color, rgb);
  }
}

}  // namespace

void DrawLabelOverlay(const RigCamera& camera, const LabelRecord& label,
                      const Faces& faces, ImageU8* rgb) {
  if (faces.rows() > 0 && label.mesh.vertices.rows() > faces.maxCoeff()) {
    RenderMesh mesh;
    mesh.vertices = label.mesh.vertices;
    mesh.faces = faces;
    mesh.color = Eigen::Vector3f(0.55f, 0.75f, 1.0f);
    const PixelRays rays(camera.camera);
    VisibilityBuffer buffer;
    buffer.Reset(rgb->width, rgb->height);
    RasterizeMesh(mesh, 0, camera.cam_from_world, rays, &buffer);
    ImageU8 shaded = *rgb;
    ShadingOptions shading;
    shading.lights = {
        {camera.cam_from_world.Inverse().rotation * Eigen::Vector3d(0, 0, 1)}};
    ShadeVisible({&mesh}, buffer, camera.cam_from_world, rays, shading, &shaded);
    for (size_t i = 0; i < shaded.data.size(); ++i) {
      rgb->data[i] =
          static_cast<uint8_t>((int(rgb->data[i]) + int(shaded.data[i]) + 1) / 2);
    }
  }
  std::vector<Eigen::Vector2d> uv(kNumHandKeypoints);
  std::vector<bool> in_front(kNumHandKeypoints);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    in_front[k] = camera.ProjectWorld(label.mesh.keypoints.row(k).transpose(), &uv[k]);
  }
  const double scale = std::max(1.0, rgb->width / 640.0);
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    const int parent = kSnapParent[k];
    if (in_front[k] && in_front[parent]) {
      DrawLine(uv[parent], uv[k], 2 * scale, kFingerColor[Finger(k)], rgb);
    }
  }
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (in_front[k]) DrawDisc(uv[k], 3 * scale, kFingerColor[Finger(k)], rgb);
  }
}

void RasterOverlayWriter::Write(const std::string& output_dir, const FrameInput& frame,
                                const LabelRecord& label) const {
  for (size_t v = 0; v < frame.rig.size(); ++v) {
    const RigCamera& camera = frame.rig[v];
    ImageU8 rgb;
    try {
      if (v < frame.image_paths.size()) rgb = ReadImageFile(frame.image_paths[v]);
    } catch (const std::exception&) {
      rgb = ImageU8();
    }
    if (rgb.width != camera.camera.width() || rgb.height != camera.camera.height() ||
        rgb.channels != 3) {
      rgb = ImageU8(camera.camera.width(), camera.camera.height(), 3, 96);
    }
    DrawLabelOverlay(camera, label, faces_, &rgb);
    WriteFileAtomically(OverlayPath(output_dir, frame.id, camera.name), EncodePng(rgb));
  }
}

}  // namespace handlabel
