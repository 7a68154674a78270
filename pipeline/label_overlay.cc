#include "pipeline/label_overlay.h"

#include <cmath>

#include "capture/frame_images.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "hand/hand_skeleton.h"
#include "image/draw.h"
#include "image/image_file.h"
#include "network/detector/detector_overlay.h"
#include "pipeline/label_outputs.h"

namespace handlabel {

void DrawLabelOverlay(const RigCamera& camera, const PixelRays& rays,
                      const LabelRecord& label, const Faces& faces, ImageU8* rgb) {
  if (faces.rows() > 0 && label.mesh.vertices.rows() > faces.maxCoeff()) {
    RenderMesh mesh;
    mesh.vertices = label.mesh.vertices;
    mesh.faces = faces;
    mesh.color = Eigen::Vector3f(0.55f, 0.75f, 1.0f);
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
  if (label.mesh.keypoints.rows() != kNumHandKeypoints) return;  // no skeleton to draw
  std::vector<Eigen::Vector2d> uv(kNumHandKeypoints);
  std::vector<bool> in_front(kNumHandKeypoints);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    in_front[k] = camera.ProjectWorld(label.mesh.keypoints.row(k).transpose(), &uv[k]);
  }
  const double scale = std::max(1.0, rgb->width / 640.0);
  for (int k = 1; k < kNumHandKeypoints; ++k) {
    const int parent = kSnapParents[k];
    if (in_front[k] && in_front[parent]) {
      DrawThickLine(rgb, uv[parent], uv[k], 2 * scale, SnapKeypointColor(k));
    }
  }
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (in_front[k]) DrawDisc(rgb, uv[k], 3 * scale, SnapKeypointColor(k));
  }
}

void RasterOverlayWriter::Write(const std::string& output_dir, const FrameInput& frame,
                                const LabelRecord& label) const {
  const std::optional<FrameHandResult> detection =
      detections_ ? detections_->Find(frame.id) : std::nullopt;
  for (size_t v = 0; v < frame.rig.size(); ++v) {
    const RigCamera& camera = frame.rig[v];
    // Grey only for a view without an image file; a file that cannot be read or does
    // not fit the camera fails the frame (the error names it), never a grey overlay.
    ImageU8 rgb = FrameViewImageRgb(frame, v);
    if (rgb.empty()) rgb = ImageU8(camera.camera.width(), camera.camera.height(), 3, 96);
    DrawLabelOverlay(camera, *rays_.Get(camera.camera), label, faces_, &rgb);
    if (detection && v < detection->views.size()) {
      DrawHandDetection(detection->views[v], &rgb);
    }
    WriteFileAtomically(OverlayPath(output_dir, frame.id, camera.name, format_),
                        format_ == "png" ? EncodePng(rgb) : EncodeJpeg(rgb, {90}));
  }
}

}  // namespace handlabel
